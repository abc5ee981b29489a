// Exact borders (the default: SimplifyOptions::exact_border; `--penalty-borders` for GH97's penalty): an open border's vertices never
// leave the input's border polylines. GH97 §6's border planes are a penalty that the optimal
// placement trades against the faces' planes, so a border vertex drifts off its border and off
// the plane of a flat patch; tiles simplified one by one then no longer meet. Here the planes
// still rank the contractions (they say what cutting a curved border costs), but a contraction
// that involves a border vertex is placed on the input's border (border_chains.h):
//   - a border vertex and an interior one: at the minimiser of the quadric restricted to the
//     border vertex's own input border between its two current border neighbours (neither
//     reached), or at the border vertex, whichever has the lowest error and flips no face
//     (place_on_own_border; a corner stays at its place);
//   - the two ends of a border edge: at the minimiser of the quadric restricted to the input
//     border between them (each input border edge of that stretch, GH97 §4's segment placement
//     on each), or at either end, whichever has the lowest error and turns no face by more than
//     the inversion limit (the next lowest otherwise): a border vertex slides along its own
//     polyline, and one that stays or lands on another's place keeps bit-identical coordinates;
//   - two border vertices that do not share a border edge: never (it would join two stretches of
//     border across the surface);
//   - a hard corner (where the border is not a simple chain, or on a non-manifold edge) is never
//     removed nor moved: its pairs are placed at it, and no vertex slides past one;
//   - a soft corner (where the border turns by more than kCornerDegrees) is kept the same way
//     with an interior vertex, and no vertex slides past its input place; along the border it
//     may be removed, at an error of at least its distance from the border that replaces it
//     (corner_error): corners at the scale of the current error, so a scan's jagged hole loses
//     its noise while a square keeps its corners.
// Locked vertices (vertex_lock, --lock-border) count as hard corners.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/context.h"
#include "core/placement.h"
#include "core/valid_pairs.h"
#include "core/working_mesh.h"

namespace qem::core {

/// A border vertex whose two border edges turn by more than this (degrees) is a corner: kept
/// exactly. A square's, a rectangle's or a hexagon's corners are kept; a polygon of 8 or more
/// sides is a curve, free to lose vertices. Smaller angles froze whole borders: scanned borders
/// are jagged, and small holes are polygons of a dozen sides; at 20 degrees plane_holes.obj
/// (27 holes) could not go below 391 faces and its E at 1 % was 40 times GH97's penalty's
/// (docs/benchmarks.md, "Borders").
inline constexpr double kCornerDegrees = 45;

/// A soft corner's size is measured between the nearest corners at most this many input border
/// edges away on either side (mark_border_corners).
inline constexpr std::size_t kCornerWalk = 64;

/// A border vertex slides at most this many input border edges per contraction (the stretch
/// between the two ends is walked edge by edge); a longer stretch is placed at either end.
inline constexpr std::size_t kMaxBorderWalk = 4096;

/// Marks mesh.corner from the input's unique edges (with face counts): ends of non-manifold
/// edges, border vertices with other than two border edges, and border turns above kCornerDegrees;
/// and builds mesh.chains and mesh.border_spot (each border vertex at its own slot).
void mark_border_corners(WorkingMesh& mesh, const std::vector<Edge>& edges);

/// The placement of border edge (a, b) whose ends may both move (BorderTarget::AtEither): the
/// lowest-error non-flipping point of the input border between them, ends included (above).
void place_along_border(const Context& c, std::uint32_t a, std::uint32_t b, const Quadric& q, Placed& placed);

/// The placement of (a, b) where a is a border vertex (not a corner) and b an interior one: the
/// lowest-error non-flipping point of a's own input border between its two current border
/// neighbours (neither reached), a's place included: a slides along its polyline.
void place_on_own_border(const Context& c, std::uint32_t a, std::uint32_t b, const Quadric& q, Placed& placed);

/// mesh.corner values: a hard corner (a border's end, a vertex where borders meet, on a
/// non-manifold edge) is never removed nor moved; a soft one (a turn above kCornerDegrees) stays
/// until the run's error reaches its size (corner_error below).
inline constexpr std::uint8_t kHardCorner = 1, kSoftCorner = 2;

/// Where the contraction of (a, b) may go under exact borders.
enum class BorderTarget : std::uint8_t { Free, AtA, AtB, AtEither, Never };

namespace border_detail {
enum class Role : std::uint8_t { Free, Border, Corner, Fixed };
inline Role role(const Context& c, std::uint32_t v) {
  const WorkingMesh& m = c.mesh;
  if (m.corner[v] == kHardCorner || m.held(v, c.settings.lock_border)) return Role::Fixed;
  if (m.corner[v] == kSoftCorner) return Role::Corner;
  return m.boundary[v] ? Role::Border : Role::Free;
}
/// Exactly one live face has both a and b: (a, b) is an edge of the current border.
/// A fan's hub (a triangulated n-gon: any number of faces) is counted from its other end, so its
/// faces are not walked on every re-cost of its pairs (that made a 30k fan cubic in its valence).
/// Only there: within a pass (order_passes.h) a survivor's list lacks the faces it absorbed, and
/// below the hub's size the end counted from stays a, as it always was.
inline constexpr std::size_t kHubFaces = 64;
inline bool is_border_edge(const WorkingMesh& m, std::uint32_t a, std::uint32_t b) {
  if (m.vertex_faces[a].size() > kHubFaces && m.vertex_faces[b].size() < m.vertex_faces[a].size()) std::swap(a, b);
  int shared = 0;
  for (std::uint32_t f : m.vertex_faces[a])
    if (m.face_alive[f] && m.face_has(f, b)) ++shared;
  return shared == 1;
}
}  // namespace border_detail

/// The rule above for pair (a, b); Free when exact borders are off or neither end is on a border.
/// A soft corner counts as a border vertex here: whether it may leave its place is priced by
/// corner_error.
inline BorderTarget border_target(const Context& c, std::uint32_t a, std::uint32_t b) {
  using border_detail::Role;
  if (!c.settings.exact_border) return BorderTarget::Free;
  const Role ra = border_detail::role(c, a), rb = border_detail::role(c, b);
  if (ra == Role::Free && rb == Role::Free) return BorderTarget::Free;
  if (ra == Role::Fixed && rb == Role::Fixed) return BorderTarget::Never;
  if (ra == Role::Free) return BorderTarget::AtB;
  if (rb == Role::Free) return BorderTarget::AtA;
  // Both on a border: only along one of its edges.
  if (!border_detail::is_border_edge(c.mesh, a, b)) return BorderTarget::Never;
  if (ra == Role::Fixed) return BorderTarget::AtA;
  if (rb == Role::Fixed) return BorderTarget::AtB;
  return BorderTarget::AtEither;
}

/// Corners at the scale of the error: the contraction of border edge (a, b) to x removes a soft
/// corner at a or b unless x is that corner's place. Its error is then at least the corner's size
/// d (BorderChains::corner_size: its distance from the line between the nearest input corners on
/// either side, a property of the input, so no pair's cost goes stale), as a quadric error
/// over `weight` (weight * d^2: sqrt(Q / weight) is the error in distance units, cost_model.h),
/// so the run removes a corner only once its error has grown to the corner's size: scan noise
/// (jagged holes) goes early, a square's corners stay unless the target asks for more than their
/// error. 0 when neither end is a soft corner that leaves.
double corner_error(const Context& c, std::uint32_t a, std::uint32_t b, const Vec3& x, double weight);

/// The border a contraction leaves must stay near the input's (GH97 §4's boundary planes do not
/// see it): when (a, b) goes to x (at input border spot `xs`), each current border neighbour n of
/// a or b gets a new border edge n-x, a chord across the input border polyline between n and x.
/// Its error is at least the farthest that polyline's input vertices lie from the chord (as a
/// quadric error over `weight`, weight * d^2, as corner_error). The constraint planes through
/// each input border edge, perpendicular to its face, measure how far x leaves them, not how far
/// the removed border lies from the chord: along a concave stretch of a rim the chord runs inside
/// the hole (in the surface's plane, across the planes' sides they do not price), the face on it
/// covers part of the hole, and the rim lies outside the output (bunny's base at 1 %: Hausdorff
/// 1.31x meshoptimizer's). 0 when no border edge changes (x is a border end's own place and the
/// other end is interior), when the contraction closes a hole, or when x is not on a border.
double chord_error(const Context& c, std::uint32_t a, std::uint32_t b, const Vec3& x, const BorderSpot& xs, double weight);

/// chord_error of one contraction (a, b) at several places, as the border placements weigh their
/// candidates: the current border neighbours of a and b, and of those neighbours, do not depend on
/// the place, so they are found once (at the first place that moves a border end), not per place.
class ChordError {
 public:
  ChordError(const Context& c, std::uint32_t a, std::uint32_t b, double weight)
      : c_(c), a_(a), b_(b), weight_(weight) {}
  double operator()(const Vec3& x, const BorderSpot& xs);

 private:
  void find_neighbours();
  const Context& c_;
  std::uint32_t a_, b_;
  double weight_;
  bool found_ = false;
  bool closes_hole_ = false;
  std::uint32_t nbr_[2][2];             // per end (a, b): its current border neighbours but the other end
  const BorderSpot* avoid_[2][2] = {};  // per such neighbour: the spot its way to the place must not pass
};

/// Small holes close at the scale of the error (as --prune removes parts in distance units): when
/// an input hole (a simple closed border loop) is down to three vertices a, b, c, contracting its
/// edge (a, b) joins its two other edges into one interior edge and the hole is gone. The link
/// condition allows it (c is the one common neighbour it tolerates, collapse_checks.h), at an
/// error of at least the hole's size: half its input loop's bounding-box diagonal, about the
/// farthest the closing surface lies from the input (hole_error, weight * r^2 as in corner_error).
/// So a hole closes only once the run's error has grown to its size: a scan's small holes go at
/// coarse targets, where GH97's penalty would have pulled their vertices off the border anyway;
/// every border that remains is exact. Returns c, or kNoVertex when (a, b) is not such an edge.
std::uint32_t hole_closed_by(const WorkingMesh& m, std::uint32_t a, std::uint32_t b);
/// The least error of the contraction of (a, b) when it closes a hole (above), else 0.
double hole_error(const WorkingMesh& m, std::uint32_t a, std::uint32_t b, double weight);
/// After a hole closed: v is a border vertex no more unless another border passes through it.
void update_border_after_closing(WorkingMesh& m, std::uint32_t v);

}  // namespace qem::core
