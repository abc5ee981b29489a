// The one check every algorithm makes on a caller's mesh before reading it. The readers already
// refuse such files with a file and line; this guards the library's plain-array entry points
// (simplify, refit, measure, analyze, mesh_info, cluster) and the writers.
#pragma once

#include <string_view>

#include "qem/mesh.h"

namespace qem {

/// Throws qem::Error if `positions` or `indices` do not come in threes, an index names no vertex,
/// or a coordinate is infinite or NaN (of any vertex, used or not: a reader refuses those too), an
/// attribute has the wrong count of values or a non-finite one, or face_materials is not one per
/// face.
/// The message starts with `what`, the caller's word for the mesh, and names the first bad
/// element: "original: face 12 refers to vertex 80, but there are only 64 vertices".
void check_mesh(MeshView mesh, std::string_view what);

}  // namespace qem
