// The refit of qem/refit.h against weighted points rather than a mesh, so that `simplify` can
// refit its output after it has released the input's faces (it keeps the per-vertex weights).
#pragma once

#include <span>
#include <vector>

#include "qem/mesh.h"
#include "qem/refit.h"

namespace qem::refit_detail {

/// A third of the area of each face around each vertex: the vertex's share of the surface, so
/// that sums over vertices approximate integrals over the surface (HG99 §2's area weighting).
/// Throws qem::Error on an out-of-range index or a non-finite coordinate.
std::vector<double> vertex_areas(MeshView mesh);

/// Refits `approx` to the points (3 doubles each) with the given weights; weight 0 = ignored.
RefitResult refit_to_points(std::span<const double> points, std::span<const double> weights, Mesh& approx,
                            const RefitOptions& options);

}  // namespace qem::refit_detail
