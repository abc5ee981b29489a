// Choosing the position of the vertex that replaces a contracted pair (GH97 §4).
#pragma once

#include <cmath>
#include <limits>

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

/// The best point on segment p1-p2 (GH97 §4), or false if q is flat along the segment.
bool place_on_segment(const Quadric& q, const Vec3& p1, const Vec3& p2, Placed& out);

/// The best of p1, p2 and their midpoint ("fixed placement" in GH97 Fig. 6).
Placed place_at_endpoints(const Quadric& q, const Vec3& p1, const Vec3& p2);

/// place_optimal's decision and solve for an A that det(A) alone does not prove well conditioned
/// (on its eigenvalues).
bool place_optimal_near_singular(const Quadric& q, Vec3& out);

// A is treated as invertible when its smallest eigenvalue is at least this fraction of its
// largest. The test is on a ratio, so scaling the model by s (A scales by s^2 or s^0 depending on
// the weighting) never changes the decision. QSlim 2.1's absolute determinant test (1e-12) is what
// rejects most optimal solves on small-scale models; this one cannot.
inline constexpr double kMinEigenRatio = 1e-7;

// When det(A) alone proves A well conditioned, the closed-form inverse is used and the
// eigen-decomposition skipped. With eigenvalues 0 <= l0 <= l1 <= l2 summing to the trace t,
// l1 l2 <= (t/2)^2 and l2 <= t, so l0 / l2 >= 4 det / t^3 = (4/27) det / (t/3)^3. Above
// kFastRatio that is at least 1.5e-6: fifteen times kMinEigenRatio, so the eigen test would accept
// A too, and a condition number below 7e5, so the cofactor solve keeps at least 10 of the 16
// digits, far more than the float output and keys hold. The bound is what decides for most pairs
// of a smooth surface (two small eigenvalues); creases and corners get the eigen test.
inline constexpr double kFastRatio = 1e-5;

/// Minimiser of q if A is invertible in the scale-relative sense, else false. Inline (as place):
/// every pair's cost runs it.
inline bool place_optimal(const Quadric& q, Vec3& out) {
  const double trace = q.a00 + q.a11 + q.a22;
  if (!(trace > 0)) return false;
  const double det = q.a00 * (q.a11 * q.a22 - q.a12 * q.a12) - q.a01 * (q.a01 * q.a22 - q.a12 * q.a02) +
                     q.a02 * (q.a01 * q.a12 - q.a11 * q.a02);
  // Cofactors of the symmetric A: its inverse times det, and on the diagonal the principal 2x2
  // minors, whose sum c1 = l0 l1 + l0 l2 + l1 l2 bounds the ratio below.
  const double i00 = q.a11 * q.a22 - q.a12 * q.a12;
  const double i01 = q.a02 * q.a12 - q.a01 * q.a22;
  const double i02 = q.a01 * q.a12 - q.a02 * q.a11;
  const double i11 = q.a00 * q.a22 - q.a02 * q.a02;
  const double i12 = q.a01 * q.a02 - q.a00 * q.a12;
  const double i22 = q.a00 * q.a11 - q.a01 * q.a01;
  const double t3 = trace / 3;
  if (!(det > kFastRatio * t3 * t3 * t3)) {
    // A fine smooth surface gives two small eigenvalues, below the bound above but far above
    // kMinEigenRatio. With l0 <= l1 <= l2 >= 0: l1 l2 <= c1 <= 3 l1 l2 and t/3 <= l2 <= t, so
    // det / (c1 t) <= l0 / l2 <= 9 det / (c1 t). Where these bounds, widened by the rounding of det
    // and c1 (a few ulps of t^3 and t^2), decide the eigen test, it is skipped; only the band
    // between them asks the eigen-decomposition.
    const double c1 = i00 + i11 + i22;
    const double det_error = 32 * std::numeric_limits<double>::epsilon() * trace * trace * trace;
    const double c1_error = 8 * std::numeric_limits<double>::epsilon() * trace * trace;
    if (9 * (det + det_error) < kMinEigenRatio * (c1 - c1_error) * trace) return false;  // l0 / l2 surely below
    if (!(det - det_error > kMinEigenRatio * (c1 + c1_error) * trace)) return place_optimal_near_singular(q, out);
  }
  const double inv = -1.0 / det;
  out = {(i00 * q.b0 + i01 * q.b1 + i02 * q.b2) * inv, (i01 * q.b0 + i11 * q.b1 + i12 * q.b2) * inv,
         (i02 * q.b0 + i12 * q.b1 + i22 * q.b2) * inv};
  return std::isfinite(out.x) && std::isfinite(out.y) && std::isfinite(out.z);
}

/// Places the contraction of (p1, p2) under quadric q according to `policy`.
/// Optimal: the minimiser of q when A is well conditioned (a scale-relative test on its
/// eigenvalues, so the same mesh at any scale makes the same choices); otherwise the best point on
/// the segment p1-p2; otherwise the best of p1, p2 and the midpoint (GH97 §4's fallback chain).
inline Placed place(const Quadric& q, const Vec3& p1, const Vec3& p2, Placement policy) {
  Placed out;
  switch (policy) {
    case Placement::Optimal:
      if (place_optimal(q, out.position)) {
        out.error = q.evaluate(out.position);
        return out;
      }
      [[fallthrough]];
    case Placement::Segment:
      if (place_on_segment(q, p1, p2, out)) return out;
      return place_at_endpoints(q, p1, p2);
    case Placement::Midpoint: {
      const Vec3 mid = (p1 + p2) * 0.5;
      return {mid, q.evaluate(mid)};
    }
    case Placement::Endpoints:
      return place_at_endpoints(q, p1, p2);
  }
  return place_at_endpoints(q, p1, p2);
}

}  // namespace qem::core
