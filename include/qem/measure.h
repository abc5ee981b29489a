// Approximation error between two surfaces (GH97 §6.1): E_i, Hausdorff, RMS and mean distance
// from points sampled uniformly by area on both surfaces.
//
// E = (sum_{v in X_n} d^2(v, M_i) + sum_{v in X_i} d^2(v, M_n)) / (|X_n| + |X_i|), where X_n are
// samples on the original M_n, X_i samples on the approximation M_i and d the exact distance to the
// nearest point of the other surface. The field names match the benchmark's metric tool, and so do
// the sampling scheme and generator (xoshiro256**), so both report the same numbers.
//
// With attributes (Mesh::attributes) on both meshes it also reports the attribute error of the
// benchmark's attr_metric.py: UV, normal and colour differences at the original's samples, and the
// cracks opened along seams.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "qem/mesh.h"

namespace qem {

struct MeasureOptions {
  std::size_t samples = 1000000;  ///< points in total, split between the surfaces by area
  std::uint64_t seed = 1;         ///< original sampled with stream 2*seed, approximation with 2*seed+1
  bool include_vertices = true;   ///< Hausdorff also over each surface's vertices (as the bench metric)
  bool per_vertex = false;        ///< fill MeasureResult::vertex_distance (approx vertices -> original)
  unsigned threads = 0;           ///< worker threads; 0 = all hardware threads. Never changes the result.
};

struct MeasureResult {
  double E = 0, E_rel = 0;                                    ///< mean squared distance over both sample sets
  double rms = 0, rms_rel = 0;                                ///< sqrt(E)
  double mean = 0, mean_rel = 0;                              ///< mean distance over both sample sets
  double hausdorff = 0, hausdorff_rel = 0;                    ///< symmetric
  double h_original_to_approx = 0, h_approx_to_original = 0;  ///< one-sided maxima
  double mean_original_to_approx = 0, mean_approx_to_original = 0;
  double rms_original_to_approx = 0, rms_approx_to_original = 0;
  double bbox_diag = 0;  ///< of the original's referenced vertices; the *_rel values divide by it
  double area_original = 0, area_approx = 0;
  std::size_t samples_original = 0, samples_approx = 0;
  std::size_t degenerate_original = 0, degenerate_approx = 0;  ///< zero-area faces, ignored
  std::vector<double> vertex_distance;                         ///< per approx vertex (all of them), if asked

  // Attribute error (docs/measure.md), as the benchmark's attr_metric.py defines it: at each sample
  // on the original (samples_original of them), the approximation's attributes interpolated at its
  // closest point against the original's at the sample. Empty when either mesh lacks the attribute.
  std::optional<double> uv_rms;          ///< RMS distance of the TexCoord (u, v), in UV units
  std::optional<double> normal_rms_deg;  ///< RMS angle between the interpolated unit Normals, degrees
  std::optional<double> color_rms;       ///< RMS of the RGBA difference (Color, 0..1; alpha 1 if absent)
  /// True when the closest points were searched among the faces of the sample's material only (both
  /// meshes have the same set of face_materials, more than one).
  bool attributes_by_material = false;
  /// Boundary edges (used by one face) after welding vertices of equal position, of each mesh, and
  /// max(0, out - in): the cracks an approximation opened along seams.
  std::size_t cracks_in = 0, cracks_out = 0, seam_cracks = 0;
};

/// Throws qem::Error when a mesh has an out-of-range index, a non-finite coordinate or attribute
/// value, an attribute or face_materials of the wrong size, or no face of non-zero area.
MeasureResult measure(MeshView original, MeshView approx, const MeasureOptions& options = {});

}  // namespace qem
