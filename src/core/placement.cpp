#include "core/placement.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace qem::core {

bool place_optimal_near_singular(const Quadric& q, Vec3& out) {
  // Decided on the eigenvalues themselves (relative), then solved in the eigenbasis.
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

}  // namespace qem::core
