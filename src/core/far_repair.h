// After the last contraction (and the refit): local repairs of the places where the output is
// farthest from the input (the Hausdorff distance), each made only where it lowers the local
// largest distance both ways and does not raise the local share of E (GH97 §6.1) beyond a margin:
//   - the larger of the largest distance from the faces' sample points to the input surface and
//     the largest distance from the input points nearest to those faces to them.
//
// Edge flips. GH97's contraction order and placement leave some output edges across a groove or
// a ridge of the input: the edge's two faces span it, the vertices lie on it, and the far points
// are near the middle of the edge (docs/benchmarks.md, "Far places"). Of the two diagonals of the
// quadrilateral those two faces form, the other may follow the groove. A flip (Hoppe et al. 1993
// §4, the "edge swap" of their mesh optimisation, here scored by the largest distance instead of
// the energy) replaces faces (a,b,c), (b,a,d) by (a,d,c), (b,c,d). It is refused where it would
// change the mesh's topology or fold it: the edge must be interior and manifold, the new edge must
// not exist, no new crease may be sharper than `max_normal_turn_degrees` unless it replaces one at
// least as sharp, and none of the four vertices may be held (locked, or on a seam).
//
// Vertex moves. A small bump of the input can be cut off by one output vertex: the bump's top is
// the farthest input point, next to that vertex, and the refit (least squares over all the points
// near the vertex) barely moves it. The farthest input points pull the nearest interior corner of
// their closest face toward them (all the way, or half way); no face of the vertex turns by more
// than `max_normal_turn_degrees`. Border, seam and locked vertices never move.
//
// Borders and faces of different materials stay as they are. Deterministic: repairs are tried one
// at a time in a fixed order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "core/distance_bound.h"
#include "geometry/frame.h"
#include "qem/mesh.h"

namespace qem::core {

struct FarRepairOptions {
  /// Per output vertex: 1 = held: no flip may add or remove an edge at it and it does not move
  /// (locked vertices, seam wedges). Empty: none held.
  std::span<const std::uint8_t> held;
  /// Only edges of faces whose local largest distance is at least this fraction of the output's
  /// largest are tried (the Hausdorff distance is a maximum: the far places are where it is won).
  /// 0.75 won the same Hausdorff distances as 0.5 on the benchmark meshes for fewer tries; lower
  /// fractions flip for E away from the far places (docs/benchmarks.md, "Far places").
  double from_fraction = 0.75;
  /// Sweeps over those edges; a sweep that flips nothing ends the pass.
  unsigned sweeps = 4;
  /// A flip may raise its faces' share of E (both sides' squared distances over their area) by at
  /// most this fraction.
  double error_margin = 0;
  /// No new crease sharper than this (the angle between the normals of two faces of an edge),
  /// unless the crease it replaces is at least as sharp (SimplifyOptions::max_normal_turn_degrees).
  double max_normal_turn_degrees = 75;
  unsigned threads = 1;
  /// After the flips, move interior vertices toward the farthest input points near them.
  bool move_vertices = true;
};

struct FarRepairResult {
  std::size_t flips = 0;
  /// Before the flips, the largest distance (in the surface's frame) of the output's face
  /// centroids and edge midpoints to the input, and of the input's points to the output.
  double largest_before = 0;
  std::size_t moves = 0;  ///< vertices moved (a vertex moved twice counts twice)
};

/// Repairs the far places of `approx` (positions in model units; `frame` maps them to the
/// surface's frame). `surface`: the input's triangles in that frame. `points` (3 per point, in the
/// frame) and `weights` (each one's share of the input's area, in model units): the input's
/// vertices (refit_detail::FitPoints). approx.indices change by flips, and the positions of the
/// moved vertices; the counts of faces and vertices stay.
FarRepairResult repair_far_places(Mesh& approx, const Frame& frame, const SurfaceDistance& surface,
                                  std::span<const double> points, std::span<const double> weights,
                                  const FarRepairOptions& options);

}  // namespace qem::core
