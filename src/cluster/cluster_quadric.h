// The quadric of a vertex cluster (Lindstrom 2000, §3): the sum of the area-weighted plane quadrics
// of the faces touching the cluster, minimised with a truncated pseudo-inverse around the cluster
// mean, so directions in which the quadric is flat (a planar or cylindrical cluster) keep the mean.
#pragma once

#include <cstddef>

namespace qem::cluster_detail {

/// Q(x) = x^T A x - 2 b^T x + c, A symmetric (6 entries).
struct ClusterQuadric {
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0;
  double b0 = 0, b1 = 0, b2 = 0;
  double c = 0;

  /// Adds the plane n.x = n.p through point p (n of unit length) with weight w.
  void add_plane(const double n[3], const double p[3], double w) {
    const double d = n[0] * p[0] + n[1] * p[1] + n[2] * p[2];
    a00 += w * n[0] * n[0], a01 += w * n[0] * n[1], a02 += w * n[0] * n[2];
    a11 += w * n[1] * n[1], a12 += w * n[1] * n[2], a22 += w * n[2] * n[2];
    b0 += w * d * n[0], b1 += w * d * n[1], b2 += w * d * n[2];
    c += w * d * d;
  }
  double evaluate(const double x[3]) const {
    const double ax0 = a00 * x[0] + a01 * x[1] + a02 * x[2];
    const double ax1 = a01 * x[0] + a11 * x[1] + a12 * x[2];
    const double ax2 = a02 * x[0] + a12 * x[1] + a22 * x[2];
    return x[0] * ax0 + x[1] * ax1 + x[2] * ax2 - 2 * (b0 * x[0] + b1 * x[1] + b2 * x[2]) + c;
  }
};

/// Eigenvalues below this fraction of the largest count as zero: relative, so the test does not
/// depend on the mesh's scale or on the total face area of the cluster.
constexpr double kRelativeEigenTolerance = 1e-3;

/// Writes argmin Q restricted to the well-conditioned eigen-directions of A, the rest taken from
/// `mean`: x = mean + A^+ (b - A mean). Returns how many directions were solved (0..3).
int minimize_around(const ClusterQuadric& q, const double mean[3], double x[3]);

}  // namespace qem::cluster_detail
