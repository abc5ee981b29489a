// Shape analysis of a mesh after HG99 §4-5 ("Optimal triangulation and quadric-based surface
// simplification", Heckbert & Garland 1999): triangle aspect ratios, the eigen-structure of each
// vertex's area-weighted quadric, the curvature it implies, the optimal aspect ratio that known
// principal curvatures predict, and the two pictures of GH97 (Fig. 11 error ellipsoids, Fig. 19
// valid pairs).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "qem/mesh.h"

namespace qem {

/// HG99 §3.2: the ratio of the major to the minor axis of the least-area ellipse through the three
/// corners (the Steiner circumellipse). With squared edge lengths a2, b2, c2, S = a2 + b2 + c2 and
/// Z = sqrt(a2^2 + b2^2 + c2^2 - a2 b2 - b2 c2 - c2 a2), the semi-axes are sqrt(S +- 2Z) / 3, so the
/// ratio is (S + 2Z) / (4 sqrt(3) area). 1 for an equilateral triangle, +inf for a degenerate one.
double triangle_aspect_ratio(const double p0[3], const double p1[3], const double p2[3]);

/// HG99 eq. (34): the L2-optimal aspect ratio sqrt(|k_large / k_small|) of triangles around a point
/// with principal curvatures k1, k2 (>= 1; +inf when exactly one is zero, 1 when both are).
double optimal_aspect_ratio(double k1, double k2);

struct AnalyzeOptions {
  /// Names of per-vertex principal-curvature properties; when both exist in the mesh, the optimal
  /// aspect ratio of every triangle is computed from their averages over its corners.
  std::string k1_property = "k1", k2_property = "k2";
};

/// Everything `qem analyze` reports. Arrays are flat: per triangle, per vertex, or 3 / 9 per vertex.
struct Analysis {
  // --- per triangle -------------------------------------------------------------------------------
  std::vector<double> area;            ///< triangle area
  std::vector<double> aspect;          ///< triangle_aspect_ratio (+inf when degenerate)
  std::vector<double> optimal_aspect;  ///< from k1, k2 properties; empty when the mesh has none

  // --- per vertex: the quadric A = sum over incident faces of area * n n^T (HG99 eq. 18) ---------
  /// Eigenvalues of A, ascending (3 per vertex). HG99 §5: the two smallest belong to the principal
  /// directions (smallest = least curvature), the largest to the normal.
  std::vector<double> eigenvalues;
  /// Unit eigenvectors (9 per vertex: e_min, e_mid, e_max, 3 coordinates each).
  std::vector<double> eigenvectors;
  /// Principal-curvature magnitudes implied by A (2 per vertex: along e_min, along e_mid), from
  /// HG99 eq. (25)-(26): a_ii = k_i^2 * integral of u_i^2 dA, so |k_i| = sqrt(lambda_i / m_i), with
  /// m_i the second moment of the incident faces' area along e_i (faces lumped at their centroids).
  /// 0 when the vertex has no face or a zero moment.
  std::vector<double> curvature;
  /// The curvature aspect ratio sqrt(lambda_mid / lambda_min) * sqrt(m_min / m_mid) = |k_mid/k_min|
  /// and the quadric's own ellipse ratio sqrt(lambda_mid / lambda_min). HG99 eq. (35)-(36): for
  /// optimally shaped neighbourhoods lambda_mid / lambda_min = |k_max / k_min|, so the latter is the
  /// optimal aspect ratio of eq. (34) read off the quadric alone. 2 per vertex; +inf when lambda_min is 0.
  std::vector<double> quadric_ratio;
  std::vector<std::uint32_t> valence;  ///< incident faces per vertex (0 = unreferenced)

  std::size_t vertex_count() const { return valence.size(); }
  std::size_t face_count() const { return aspect.size(); }
};

/// Analyses a mesh. Throws qem::Error when an index is out of range or a coordinate is not finite.
Analysis analyze(const Mesh& mesh, const AnalyzeOptions& options = {});

/// GH97 Fig. 11 / HG99 Fig. 3: one small ellipsoid per referenced vertex, centred at the vertex,
/// with axes along the eigenvectors of A and semi-axes proportional to 1/sqrt(lambda_i) (the level
/// set v^T A v = eps). `scale` times 0.15 mean edge lengths is the shortest semi-axis; the others
/// are clamped at 6 times that so flat regions (lambda ~ 0) stay finite. Each is a subdivided
/// octahedron (32 faces).
Mesh quadric_ellipsoids(const Mesh& mesh, const Analysis& analysis, double scale = 1);

/// GH97 §3.2 valid pairs: every edge (first, with `edges` set to their count) and every pair of
/// referenced vertices closer than `threshold` that is not an edge. Pairs are (i < j), sorted.
std::vector<std::pair<std::uint32_t, std::uint32_t>> valid_pairs(const Mesh& mesh, double threshold,
                                                                 std::size_t* edges = nullptr);

/// Writes `pairs` as OBJ line elements (`l i j`) over the mesh's vertices, edges in group `edges`
/// and the others in group `non_edges` (GH97 Fig. 19: red and green). Atomic write.
void save_pairs_obj(const std::string& path, const Mesh& mesh,
                    const std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs, std::size_t edges);

}  // namespace qem
