#include "cluster/cluster_quadric.h"

#include <Eigen/Dense>

namespace qem::cluster_detail {

int minimize_around(const core::Quadric& q, const double mean[3], double x[3]) {
  Eigen::Matrix3d A;
  A << q.a00, q.a01, q.a02, q.a01, q.a11, q.a12, q.a02, q.a12, q.a22;
  const Eigen::Vector3d m(mean[0], mean[1], mean[2]);
  const Eigen::Vector3d r = -Eigen::Vector3d(q.b0, q.b1, q.b2) - A * m;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(A);
  Eigen::Vector3d y = Eigen::Vector3d::Zero();
  int rank = 0;
  const double lmax = eig.eigenvalues().cwiseAbs().maxCoeff();
  if (eig.info() == Eigen::Success && lmax > 0) {
    for (int k = 0; k < 3; ++k) {
      const double l = eig.eigenvalues()[k];
      if (!(l > kRelativeEigenTolerance * lmax)) continue;  // A is PSD: tiny or negative = flat
      const Eigen::Vector3d v = eig.eigenvectors().col(k);
      y += v * (v.dot(r) / l);
      ++rank;
    }
  }
  for (int k = 0; k < 3; ++k) x[k] = m[k] + y[k];
  return rank;
}

}  // namespace qem::cluster_detail
