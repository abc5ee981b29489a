// The quadric of a vertex cluster (Lindstrom 2000, §3): the sum of the area-weighted plane quadrics
// (core::Quadric, GH97 §5) of the faces touching the cluster, minimised with a truncated
// pseudo-inverse around the cluster mean, so directions in which the quadric is flat (a planar or
// cylindrical cluster) keep the mean.
#pragma once

#include "core/quadric.h"

namespace qem::cluster_detail {

/// Eigenvalues below this fraction of the largest count as zero: relative, so the test does not
/// depend on the mesh's scale or on the total face area of the cluster.
constexpr double kRelativeEigenTolerance = 1e-3;

/// Writes argmin Q restricted to the well-conditioned eigen-directions of A, the rest taken from
/// `mean`. With core::Quadric's Q(x) = x^T A x + 2 b^T x + c the minimum solves A x = -b, so
/// x = mean + A^+ (-b - A mean). Returns how many directions were solved (0..3).
int minimize_around(const core::Quadric& q, const double mean[3], double x[3]);

}  // namespace qem::cluster_detail
