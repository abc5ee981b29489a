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
// Relocations. Where neither mends the farthest place (a far point along an edge whose flip and
// whose corners' moves all make something else worse), a vertex is added there and one taken
// away where the output is flattest (Hoppe et al. 1993 §4's edge split, paired with its edge
// collapse), so that the counts of faces and vertices stay:
//   - the split: the far place's edge (or face) divides at the point nearest the farthest input
//     point, or nearest the input to the farthest sample (each face's largest sample climbed to
//     its peak first: a grid misses the peak between its points); the new vertex on the input.
//     A border edge divides at an input border vertex, so the border stays on the input's: one of
//     the input points nearest the faces round the edge, or, when none of those will do (a small
//     part kept as one face, whose input points went to nearer faces of other parts), the input
//     border vertex nearest the far place; the nearest whose faces turn nothing over. At a
//     crack (two coincident border edges, the sides of a seam the input never welded) both sides
//     divide together, a vertex more (`add_vertices`); where the sides already part, one alone.
//     At a lone spike of the input (an outlier pixel of a terrain), where faces up to its tip
//     would turn by more than `max_normal_turn_degrees`, the new vertex goes 3/4, 1/2 or 1/4 of
//     the way up instead, the highest the limit allows: the largest distance still falls.
//   - the collapse: an interior vertex whose removal moves the surface least (its distance to its
//     ring's plane, squared, times its fan's area: the share of E it would add) goes into a
//     neighbour; for a border split, a border vertex along its border (not a corner, as the
//     contractions keep them), or, when none can go, an interior one and the output ends a face
//     short (at most one face in 256).
// Made only where the largest distance falls (the split's faces below the farthest, the
// collapse's below half of it, input samples between the input's vertices included), the link
// condition holds and no face folds: each new face within the turn limit of the face it comes
// from as that face's line was before the relocations (measured from the face as it is, splits
// beside an earlier split's steep faces would add turn to turn, and fold); together they may
// raise E by at most `relocation_budget`.
// Farthest place first (border faces from 0.4 of the largest scored first: there a face's
// centroid and edge midpoints can miss its peak by a factor); a place no relocation mends is
// passed over, up to 8 in a row. With attributes the new vertex takes the values at its foot on
// the faces it divides (normals renormalised, colours clamped; skin joints from the nearest
// corner), each new face its parent's material, and the collapse must not raise the error of
// appearance (a vertex whose values the others do not interpolate stays). Not on meshes with
// vertex properties, which a new vertex would need too.
//
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/distance_bound.h"
#include "geometry/frame.h"
#include "qem/mesh.h"
#include "qem/simplify.h"

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
  /// Then at most this many relocations (0: none).
  std::size_t relocations = 0;
  /// The relocations together may raise E (estimated) by at most this fraction.
  double relocation_budget = 0.005;
  /// Per point: a face of `approx` a local search found closest (UINT32_MAX: none), such as the
  /// refit's (refit_to_points' closest_faces). A point within half the largest distance from the
  /// output's faces to the input (their centroids and edge midpoints) keeps it; the others, which
  /// could be a far place's, ask a tree of the faces, as all do when this is empty.
  std::span<const std::uint32_t> point_faces;
  /// Per point: 1 = on the input's border (points_on_border). Empty: no relocation at a border,
  /// unless find_border_points.
  std::span<const std::uint8_t> point_on_border;
  /// With point_on_border empty: the repair finds the input's border points itself
  /// (points_on_border of input_faces and point_source) when a relocation at a border first needs
  /// them, so a run whose output has no border never makes them (the input's face lists, on a
  /// closed input the largest arrays of the repair's set-up, for nothing).
  bool find_border_points = false;
  /// With attributes (approx.attributes, in the order of the input's): the input's per-vertex
  /// attributes and each point's input vertex (FitPoints::source). A flip, a move or a
  /// relocation's collapse changes where the output's values are interpolated; it is also refused
  /// where it raises the error of appearance round it: each point's values against the output's
  /// interpolated at its closest point, weighted as the metric weighs the channels
  /// (`attribute_weights`), by the points' areas. Empty: geometry alone judges.
  std::span<const VertexAttribute> input_attributes;
  std::span<const std::uint32_t> point_source;
  /// The input's faces (3 per face, those of `surface`, in its order): with them the error of
  /// appearance is also sampled on the input's faces between its vertices. Empty: vertices only.
  std::span<const std::uint32_t> input_faces;
  AttributeWeights attribute_weights;
  /// Whether a relocation may add a vertex: at a crack (two border edges at the same positions, the
  /// sides of a seam the input never welded), both sides split together, so the faces' count
  /// stays and the vertices' grows by one.
  bool add_vertices = false;
};

/// One relocation: output vertex `removed` collapsed into `kept`, and its slot holds the new
/// vertex; the two faces the collapse removed hold two of the split's faces, each divided from
/// the face in `parent` (the split divides one face, or the two of an edge).
struct Relocation {
  std::uint32_t removed = 0, kept = 0;
  /// The input point (FitPoints index) the new vertex stands at (`at_point`) or nearest to;
  /// UINT32_MAX: none.
  std::uint32_t point = UINT32_MAX;
  bool at_point = false;
  /// The new vertex's twin at a crack (appended to the vertices), or UINT32_MAX.
  std::uint32_t added = UINT32_MAX;
  /// A face slot left empty (a border split paired with an interior collapse: one face fewer), or
  /// UINT32_MAX. Such slots are dropped from approx.indices at the end, the others keeping their
  /// order; reused, parent and the other relocations' slots count them.
  std::uint32_t dropped = UINT32_MAX;
  /// UINT32_MAX in the second when a border split took one face.
  std::array<std::uint32_t, 2> reused{UINT32_MAX, UINT32_MAX}, parent{UINT32_MAX, UINT32_MAX};
};

struct FarRepairResult {
  std::size_t flips = 0;
  /// Before the flips, the largest distance (in the surface's frame) of the output's face
  /// centroids and edge midpoints to the input, and of the input's points to the output.
  double largest_before = 0;
  std::size_t moves = 0;  ///< vertices moved (a vertex moved twice counts twice)
  std::vector<Relocation> relocations;  ///< in the order made
};

/// Repairs the far places of `approx` (positions in model units; `frame` maps them to the
/// surface's frame). `surface`: the input's triangles in that frame. `points` (3 per point, in the
/// frame) and `weights` (each one's share of the input's area, in model units): the input's
/// vertices (refit_detail::FitPoints). approx.indices change by flips and relocations, and the
/// positions of the moved vertices; the counts of faces and vertices stay, but for the
/// relocations' `dropped` faces and `added` vertices.
/// Per point of `point_source` (an input vertex each, FitPoints::source): 1 where that vertex is an
/// end of an edge that only one of `indices`' faces has; the same on any number of `threads`.
std::vector<std::uint8_t> points_on_border(std::span<const std::uint32_t> indices,
                                           std::span<const std::uint32_t> point_source, unsigned threads);

FarRepairResult repair_far_places(Mesh& approx, const Frame& frame, const SurfaceDistance& surface,
                                  std::span<const double> points, std::span<const double> weights,
                                  const FarRepairOptions& options);

}  // namespace qem::core
