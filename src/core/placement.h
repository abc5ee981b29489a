// Choosing the position of the vertex that replaces a contracted pair (GH97 §4).
#pragma once

#include "core/border_chains.h"
#include "core/quadric.h"
#include "qem/simplify.h"

namespace qem::core {

struct Placed {
  Placed() = default;
  Placed(const Vec3& at, double q_error, const BorderSpot& border_spot = {})
      : position(at), error(q_error), spot(border_spot) {}
  Vec3 position;
  double error = 0;  ///< Q(position)
  /// Under exact borders, a border vertex slid along its polyline: where (border_chains.h).
  BorderSpot spot;
};

/// Places the contraction of (p1, p2) under quadric q according to `policy`.
/// Optimal: the minimiser of q when A is well conditioned (a scale-relative test on its
/// eigenvalues, so the same mesh at any scale makes the same choices); otherwise the best point on
/// the segment p1-p2; otherwise the best of p1, p2 and the midpoint (GH97 §4's fallback chain).
Placed place(const Quadric& q, const Vec3& p1, const Vec3& p2, Placement policy);

/// The best point on segment p1-p2 (GH97 §4), or false if q is flat along the segment.
bool place_on_segment(const Quadric& q, const Vec3& p1, const Vec3& p2, Placed& out);

/// The best of p1, p2 and their midpoint ("fixed placement" in GH97 Fig. 6).
Placed place_at_endpoints(const Quadric& q, const Vec3& p1, const Vec3& p2);

/// Minimiser of q if A is invertible in the scale-relative sense, else false.
bool place_optimal(const Quadric& q, Vec3& out);

}  // namespace qem::core
