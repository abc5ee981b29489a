#include "core/placement.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace qem::core {

namespace {

// A is treated as invertible when its smallest eigenvalue is at least this fraction of its
// largest. The test is on a ratio, so scaling the model by s (A scales by s^2 or s^0 depending on
// the weighting) never changes the decision. QSlim 2.1's absolute determinant test (1e-12) is what
// rejects most optimal solves on small-scale models; this one cannot.
constexpr double kMinEigenRatio = 1e-7;

// When det(A) alone proves A well conditioned, the closed-form inverse is used and the
// eigen-decomposition skipped. With eigenvalues 0 <= l0 <= l1 <= l2 summing to the trace t,
// l1 l2 <= (t/2)^2 and l2 <= t, so l0 / l2 >= 4 det / t^3 = (4/27) det / (t/3)^3. Above
// kFastRatio that is at least 1.5e-6: fifteen times kMinEigenRatio, so the eigen test would accept
// A too, and a condition number below 7e5, so the cofactor solve keeps at least 10 of the 16
// digits, far more than the float output and keys hold. The bound is what decides for most pairs
// of a smooth surface (two small eigenvalues); creases and corners get the eigen test.
constexpr double kFastRatio = 1e-5;

bool solve_closed_form(const Quadric& q, Vec3& out, double det) {
  // Cofactor inverse of the symmetric A, applied to -b.
  double i00 = q.a11 * q.a22 - q.a12 * q.a12;
  double i01 = q.a02 * q.a12 - q.a01 * q.a22;
  double i02 = q.a01 * q.a12 - q.a02 * q.a11;
  double i11 = q.a00 * q.a22 - q.a02 * q.a02;
  double i12 = q.a01 * q.a02 - q.a00 * q.a12;
  double i22 = q.a00 * q.a11 - q.a01 * q.a01;
  double inv = -1.0 / det;
  out = {(i00 * q.b0 + i01 * q.b1 + i02 * q.b2) * inv, (i01 * q.b0 + i11 * q.b1 + i12 * q.b2) * inv,
         (i02 * q.b0 + i12 * q.b1 + i22 * q.b2) * inv};
  return std::isfinite(out.x) && std::isfinite(out.y) && std::isfinite(out.z);
}

}  // namespace

bool place_optimal(const Quadric& q, Vec3& out) {
  double trace = q.a00 + q.a11 + q.a22;
  if (!(trace > 0)) return false;
  double det = q.a00 * (q.a11 * q.a22 - q.a12 * q.a12) - q.a01 * (q.a01 * q.a22 - q.a12 * q.a02) +
               q.a02 * (q.a01 * q.a12 - q.a11 * q.a02);
  double t3 = trace / 3;
  if (det > kFastRatio * t3 * t3 * t3) return solve_closed_form(q, out, det);

  // Near-singular: decide on the eigenvalues themselves (relative), then solve in the eigenbasis.
  Eigen::Matrix3d a;
  a << q.a00, q.a01, q.a02, q.a01, q.a11, q.a12, q.a02, q.a12, q.a22;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(a);
  const Eigen::Vector3d& lambda = es.eigenvalues();  // ascending
  if (!(lambda[0] > kMinEigenRatio * lambda[2])) return false;
  Eigen::Vector3d b(q.b0, q.b1, q.b2);
  Eigen::Vector3d coeff = es.eigenvectors().transpose() * b;
  Eigen::Vector3d x = -(es.eigenvectors() * coeff.cwiseQuotient(lambda));
  out = {x[0], x[1], x[2]};
  return x.allFinite();
}

bool place_on_segment(const Quadric& q, const Vec3& p1, const Vec3& p2, Placed& out) {
  // Q(p1 + s d) = Q(p1) + 2 s (A p1 + b).d + s^2 d^T A d, minimised over s in [0, 1].
  Vec3 d = p2 - p1;
  Vec3 ad = q.apply_a(d);
  double curvature = dot(d, ad);
  double trace = q.a00 + q.a11 + q.a22;
  // Relative flatness test: d^T A d compared with the largest it could be for this |d|.
  if (!(curvature > 1e-12 * trace * dot(d, d))) return false;
  Vec3 g = q.apply_a(p1) + Vec3(q.b0, q.b1, q.b2);
  double s = std::clamp(-dot(g, d) / curvature, 0.0, 1.0);
  out.position = p1 + d * s;
  out.error = q.evaluate(out.position);
  return true;
}

Placed place_at_endpoints(const Quadric& q, const Vec3& p1, const Vec3& p2) {
  Vec3 mid = (p1 + p2) * 0.5;
  Placed best{p1, q.evaluate(p1)};
  double e2 = q.evaluate(p2);
  if (e2 < best.error) best = {p2, e2};
  double em = q.evaluate(mid);
  if (em < best.error) best = {mid, em};
  return best;
}

Placed place(const Quadric& q, const Vec3& p1, const Vec3& p2, Placement policy) {
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
      Vec3 mid = (p1 + p2) * 0.5;
      return {mid, q.evaluate(mid)};
    }
    case Placement::Endpoints:
      return place_at_endpoints(q, p1, p2);
  }
  return place_at_endpoints(q, p1, p2);
}

}  // namespace qem::core
