// Attribute error of an approximation (issue 18), as the benchmark's bench/metric/attr_metric.py
// defines it: at area-uniform samples of the original, the approximation's attributes interpolated
// at the closest point (barycentric over the closest face's corner wedges) against the original's
// interpolated at the sample; plus the cracks opened along seams, counted on position-welded
// boundary edges.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "measure/bvh.h"
#include "measure/surface_sampling.h"
#include "qem/mesh.h"

namespace qem::measure_detail {

struct AttributeErrors {
  std::optional<double> uv_rms, normal_rms_deg, color_rms;  ///< empty: absent from either mesh
  bool by_material = false;  ///< closest points searched among faces of the sample's material
};

/// True when both meshes carry at least one attribute the error compares (TexCoord, Normal, Color).
bool has_comparable_attributes(MeshView original, MeshView approx);

/// The samples on the original are `samples` (xyz) at `places` on `sn`; `hits[k]` is the triangle
/// of `si` closest to sample k in `tree_i` (over the whole approximation: found by the distance
/// pass, and used unless the search is restricted by material).
AttributeErrors attribute_errors(MeshView original, const Surface& sn, MeshView approx, const Surface& si,
                                 const TriangleBvh& tree_i, const std::vector<double>& samples,
                                 const std::vector<SamplePlace>& places,
                                 const std::vector<std::uint32_t>& hits, unsigned threads);

/// Edges used by exactly one face once vertices of equal position are welded (-0 equals +0), over
/// all faces, zero-area ones included: the script's `boundary_edges`.
std::size_t welded_boundary_edges(MeshView mesh);

}  // namespace qem::measure_detail
