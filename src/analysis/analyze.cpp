// HG99 §4-5: triangle aspect ratios and the curvature information held by the per-vertex quadrics.
#include "qem/analyze.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "check_mesh.h"
#include "qem/error.h"

namespace qem {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

double triangle_aspect_ratio(const double p0[3], const double p1[3], const double p2[3]) {
  // The least-area ellipse through three points is the affine image of the circumcircle of an
  // equilateral triangle (affine maps keep area ratios), i.e. the Steiner circumellipse, centred
  // at the centroid. Its semi-axes in terms of the squared side lengths are sqrt(S +- 2Z) / 3, and
  // (S + 2Z)(S - 2Z) = 48 area^2, which gives the ratio without cancellation for thin triangles.
  double e[3][3];
  for (int k = 0; k < 3; ++k) {
    e[0][k] = p1[k] - p0[k];
    e[1][k] = p2[k] - p1[k];
    e[2][k] = p0[k] - p2[k];
  }
  double a2 = e[0][0] * e[0][0] + e[0][1] * e[0][1] + e[0][2] * e[0][2];
  double b2 = e[1][0] * e[1][0] + e[1][1] * e[1][1] + e[1][2] * e[1][2];
  double c2 = e[2][0] * e[2][0] + e[2][1] * e[2][1] + e[2][2] * e[2][2];
  double cx = e[0][1] * e[2][2] - e[0][2] * e[2][1];
  double cy = e[0][2] * e[2][0] - e[0][0] * e[2][2];
  double cz = e[0][0] * e[2][1] - e[0][1] * e[2][0];
  double area = 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
  double s = a2 + b2 + c2;
  double z2 = a2 * a2 + b2 * b2 + c2 * c2 - a2 * b2 - b2 * c2 - c2 * a2;
  double z = std::sqrt(std::max(0.0, z2));
  if (!(area > 0)) return kInf;
  return std::max(1.0, (s + 2 * z) / (4 * std::sqrt(3.0) * area));
}

double optimal_aspect_ratio(double k1, double k2) {
  double a = std::abs(k1), b = std::abs(k2);
  if (a < b) std::swap(a, b);
  if (a == 0) return 1;  // flat: any aspect ratio is optimal (HG99 §4.2); report the isotropic one
  if (b == 0) return kInf;
  return std::sqrt(a / b);
}

Analysis analyze(const Mesh& mesh, const AnalyzeOptions& options) {
  check_mesh(mesh, "analyze");
  const std::size_t nv = mesh.vertex_count(), nf = mesh.face_count();
  const double* p = mesh.positions.data();
  Analysis r;
  r.area.resize(nf);
  r.aspect.resize(nf);
  r.valence.assign(nv, 0);

  // Face normals, areas and centroids; A_v = sum of area * n n^T over incident faces (HG99 eq. 18,
  // the discrete form of the integral the area-weighted simplifier accumulates).
  std::vector<double> amat(6 * nv, 0.0), normal(3 * nf), centroid(3 * nf);
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t* t = &mesh.indices[3 * f];
    const double *a = p + 3 * t[0], *b = p + 3 * t[1], *c = p + 3 * t[2];
    r.aspect[f] = triangle_aspect_ratio(a, b, c);
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    r.area[f] = 0.5 * len;
    for (int k = 0; k < 3; ++k) {
      normal[3 * f + k] = len > 0 ? n[k] / len : 0;
      centroid[3 * f + k] = (a[k] + b[k] + c[k]) / 3;
    }
    const double* nn = &normal[3 * f];
    double ar = r.area[f];
    for (int j = 0; j < 3; ++j) {
      if (j > 0 && (t[j] == t[0] || (j == 2 && t[2] == t[1]))) continue;  // a plane counts once per vertex
      double* m = &amat[6 * t[j]];
      m[0] += ar * nn[0] * nn[0], m[1] += ar * nn[0] * nn[1], m[2] += ar * nn[0] * nn[2];
      m[3] += ar * nn[1] * nn[1], m[4] += ar * nn[1] * nn[2], m[5] += ar * nn[2] * nn[2];
      ++r.valence[t[j]];
    }
  }

  // Eigen-decomposition per vertex; ascending eigenvalues, so e_min is the least-curvature
  // direction and e_max the normal (HG99 §5).
  r.eigenvalues.assign(3 * nv, 0.0);
  r.eigenvectors.assign(9 * nv, 0.0);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  for (std::size_t v = 0; v < nv; ++v) {
    const double* m = &amat[6 * v];
    Eigen::Matrix3d a;
    a << m[0], m[1], m[2], m[1], m[3], m[4], m[2], m[4], m[5];
    solver.computeDirect(a);
    for (int i = 0; i < 3; ++i) {
      r.eigenvalues[3 * v + i] = std::max(0.0, solver.eigenvalues()(i));
      for (int k = 0; k < 3; ++k) r.eigenvectors[9 * v + 3 * i + k] = solver.eigenvectors()(k, i);
    }
  }

  // Second moments of the incident faces along e_min and e_mid: HG99 eq. (25)-(26) read
  // a_ii = k_i^2 * (4/3) eps_i^3 eps_j = k_i^2 * integral(u_i^2 dA) over the neighbourhood, because
  // the normal tilts by k_i u_i at offset u_i. A flat face carries the normal of its centroid.
  std::vector<double> moment(2 * nv, 0.0);
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t* t = &mesh.indices[3 * f];
    for (int j = 0; j < 3; ++j) {
      if (j > 0 && (t[j] == t[0] || (j == 2 && t[2] == t[1]))) continue;
      std::uint32_t v = t[j];
      double d[3];
      for (int k = 0; k < 3; ++k) d[k] = centroid[3 * f + k] - p[3 * v + k];
      for (int i = 0; i < 2; ++i) {
        const double* e = &r.eigenvectors[9 * v + 3 * i];
        double u = d[0] * e[0] + d[1] * e[1] + d[2] * e[2];
        moment[2 * v + i] += r.area[f] * u * u;
      }
    }
  }
  r.curvature.assign(2 * nv, 0.0);
  r.quadric_ratio.assign(2 * nv, 0.0);
  for (std::size_t v = 0; v < nv; ++v) {
    for (int i = 0; i < 2; ++i)
      r.curvature[2 * v + i] =
          moment[2 * v + i] > 0 ? std::sqrt(r.eigenvalues[3 * v + i] / moment[2 * v + i]) : 0;
    double l0 = r.eigenvalues[3 * v], l1 = r.eigenvalues[3 * v + 1];
    double k0 = r.curvature[2 * v], k1 = r.curvature[2 * v + 1];
    r.quadric_ratio[2 * v] = k0 > 0 ? k1 / k0 : (k1 > 0 ? kInf : 1);
    r.quadric_ratio[2 * v + 1] = l0 > 0 ? std::sqrt(l1 / l0) : (l1 > 0 ? kInf : 1);
  }

  // Optimal aspect ratio from known curvatures, averaged over the triangle's corners.
  const VertexProperty* pk1 = mesh.find_property(options.k1_property);
  const VertexProperty* pk2 = mesh.find_property(options.k2_property);
  if (pk1 && pk2 && pk1->values.size() == nv && pk2->values.size() == nv) {
    r.optimal_aspect.resize(nf);
    for (std::size_t f = 0; f < nf; ++f) {
      const std::uint32_t* t = &mesh.indices[3 * f];
      double k1 = (pk1->values[t[0]] + pk1->values[t[1]] + pk1->values[t[2]]) / 3;
      double k2 = (pk2->values[t[0]] + pk2->values[t[1]] + pk2->values[t[2]]) / 3;
      r.optimal_aspect[f] = optimal_aspect_ratio(k1, k2);
    }
  }
  return r;
}

}  // namespace qem
