#include "refit/attribute_fit.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "core/attribute_weight.h"
#include "core/faces_at_vertices.h"
#include "geometry/vec3.h"
#include "measure/point_triangle.h"

namespace qem::refit_detail {

namespace {

bool fitted(const VertexAttribute& a, const AttributeWeights& w) { return core::attribute_weight(a.kind, w) > 0; }

// Weight of the pull towards a vertex's present values, per unit of its area share: keeps the
// system definite where no sample lands near a vertex, too small to move the others.
constexpr double kHold = 1e-3;

}  // namespace

bool has_fitted_attributes(std::span<const VertexAttribute> attributes, const AttributeWeights& weights) {
  return std::any_of(attributes.begin(), attributes.end(),
                     [&](const VertexAttribute& a) { return fitted(a, weights); });
}

void fit_attributes(std::span<const double> positions, std::span<const std::uint32_t> indices,
                    std::span<const VertexAttribute> attributes, const AttributeWeights& weights,
                    std::span<const std::uint32_t> output_vertex_of_input, std::span<const std::uint8_t> held,
                    Mesh& out) {
  const std::size_t n = out.vertex_count(), faces = out.indices.size() / 3;
  std::vector<std::size_t> fit;  // the attributes fitted, and their components in a row
  std::uint32_t width = 0;
  for (std::size_t i = 0; i < attributes.size() && i < out.attributes.size(); ++i)
    if (fitted(attributes[i], weights) && out.attributes[i].components == attributes[i].components)
      fit.push_back(i), width += attributes[i].components;
  if (fit.empty() || n == 0) return;
  const auto out_pos = [&](std::uint32_t v) {
    return Vec3{out.positions[3 * v], out.positions[3 * v + 1], out.positions[3 * v + 2]};
  };

  // The output faces around each output vertex (compressed rows), and each vertex's area share.
  const core::FacesAtVertices rows = core::faces_at_vertices(out.indices, n, 1);
  const auto& start = rows.start;
  const auto& around = rows.faces;
  std::vector<double> area(n, 0);
  for (std::uint32_t f = 0; f < faces; ++f) {
    const std::uint32_t* t = &out.indices[3 * std::size_t(f)];
    const double a = length(cross(out_pos(t[1]) - out_pos(t[0]), out_pos(t[2]) - out_pos(t[0]))) / 2;
    for (int k = 0; k < 3; ++k) area[t[k]] += a / 3;
  }

  // The unknowns: the vertices not held, numbered in order.
  std::vector<std::int64_t> unknown(n, -1);
  std::int64_t unknowns = 0;
  for (std::size_t v = 0; v < n; ++v)
    if (held.empty() || !held[v]) unknown[v] = unknowns++;
  if (unknowns == 0) return;

  // Normal equations of sum over samples of weight * |sum_k lambda_k x_k - s|^2, x the unknown
  // values at the corners of the output face nearest to the sample, lambda its barycentric
  // weights there, s the input's values at the sample. The samples of an input face: its centroid,
  // or, when the output has more than a quarter of the input's faces (a few input faces per
  // output face), the centroids of its four halved-edge triangles, so that every output face
  // still gets several. The faces searched: those around the output vertices that the face's
  // corners went into (their wedges, so on the face's side of every seam). The matrix is summed
  // per output face (a 3x3 block each), the right-hand side per unknown; the held corners' share
  // moves to the right.
  static constexpr std::array<std::array<double, 3>, 4> kQuarters{{{1.0 / 3, 1.0 / 3, 1.0 / 3},
                                                                   {2.0 / 3, 1.0 / 6, 1.0 / 6},
                                                                   {1.0 / 6, 2.0 / 3, 1.0 / 6},
                                                                   {1.0 / 6, 1.0 / 6, 2.0 / 3}}};
  const std::size_t per_face = 4 * faces > indices.size() / 3 ? 4 : 1;
  std::vector<std::array<double, 6>> block(faces, std::array<double, 6>{});  // 00 01 02 11 12 22
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(unknowns, width);
  std::vector<double> s(width);
  const auto in_pos = [&](std::uint32_t v) {
    return Vec3{positions[3 * std::size_t(v)], positions[3 * std::size_t(v) + 1],
                positions[3 * std::size_t(v) + 2]};
  };
  for (std::size_t f = 0; f + 2 < indices.size(); f += 3) {
    const std::uint32_t c[3] = {indices[f], indices[f + 1], indices[f + 2]};
    const Vec3 pa = in_pos(c[0]), pb = in_pos(c[1]), pc = in_pos(c[2]);
    const double w = length(cross(pb - pa, pc - pa)) / 2 / double(per_face);
    if (!(w > 0)) continue;
    std::uint32_t o[3];
    for (int k = 0; k < 3; ++k) {
      o[k] = c[k] < output_vertex_of_input.size() ? output_vertex_of_input[c[k]] : SimplifyResult::kUnmapped;
      if (o[k] >= n || (k > 0 && o[k] == o[0]) || (k > 1 && o[k] == o[1])) o[k] = SimplifyResult::kUnmapped;
    }
    for (std::size_t at = 0; at < per_face; ++at) {
      const std::array<double, 3>& bary = kQuarters[at];
      const Vec3 p = pa * bary[0] + pb * bary[1] + pc * bary[2];
      std::uint32_t best = UINT32_MAX;  // the first found on ties
      std::array<double, 3> l{};
      double best_d2 = std::numeric_limits<double>::infinity();
      for (std::uint32_t ov : o) {
        if (ov == SimplifyResult::kUnmapped) continue;
        for (std::uint32_t i = start[ov]; i < start[ov + 1]; ++i) {
          const std::uint32_t* t = &out.indices[3 * std::size_t(around[i])];
          const Vec3 x = out_pos(t[0]), y = out_pos(t[1]), z = out_pos(t[2]);
          const std::array<double, 3> near = measure_detail::closest_point_weights(p, x, y, z);
          const double d2 = measure_detail::squared_distance(p, x * near[0] + y * near[1] + z * near[2]);
          if (d2 < best_d2) best = around[i], l = near, best_d2 = d2;
        }
      }
      if (best == UINT32_MAX) continue;
      const std::uint32_t* t = &out.indices[3 * std::size_t(best)];
      std::array<double, 6>& b = block[best];
      b[0] += w * l[0] * l[0], b[1] += w * l[0] * l[1], b[2] += w * l[0] * l[2];
      b[3] += w * l[1] * l[1], b[4] += w * l[1] * l[2], b[5] += w * l[2] * l[2];
      std::uint32_t j = 0;
      for (std::size_t i : fit) {
        const VertexAttribute& from = attributes[i];
        const VertexAttribute& to = out.attributes[i];
        for (std::uint32_t k = 0; k < from.components; ++k, ++j) {
          s[j] = 0;
          for (int q = 0; q < 3; ++q) s[j] += bary[q] * from.values[std::size_t(c[q]) * from.components + k];
          for (int q = 0; q < 3; ++q)
            if (unknown[t[q]] < 0) s[j] -= l[q] * to.values[std::size_t(t[q]) * to.components + k];
        }
      }
      for (int r = 0; r < 3; ++r)
        if (unknown[t[r]] >= 0 && l[r] != 0)
          for (std::uint32_t k = 0; k < width; ++k) rhs(unknown[t[r]], k) += w * l[r] * s[k];
    }
  }
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(9 * faces + n);
  for (std::uint32_t f = 0; f < faces; ++f) {
    const std::uint32_t* t = &out.indices[3 * std::size_t(f)];
    const std::array<double, 6>& b = block[f];
    const double m[3][3] = {{b[0], b[1], b[2]}, {b[1], b[3], b[4]}, {b[2], b[4], b[5]}};
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q)
        if (unknown[t[r]] >= 0 && unknown[t[q]] >= 0 && m[r][q] != 0)
          entries.emplace_back(unknown[t[r]], unknown[t[q]], m[r][q]);
  }
  std::vector<std::array<double, 6>>().swap(block);
  // The pull towards the present values.
  for (std::size_t v = 0; v < n; ++v) {
    if (unknown[v] < 0) continue;
    const double h = kHold * area[v];
    entries.emplace_back(unknown[v], unknown[v], h);
    std::uint32_t j = 0;
    for (std::size_t i : fit) {
      const VertexAttribute& to = out.attributes[i];
      for (std::uint32_t k = 0; k < to.components; ++k, ++j)
        rhs(unknown[v], j) += h * to.values[v * to.components + k];
    }
  }
  Eigen::SparseMatrix<double> m(unknowns, unknowns);
  m.setFromTriplets(entries.begin(), entries.end());
  std::vector<Eigen::Triplet<double>>().swap(entries);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(m);
  if (solver.info() != Eigen::Success) return;  // keeps the placement's values
  const Eigen::MatrixXd x = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !x.allFinite()) return;

  // The new values, normals unit, colours in [0, 1], texture coordinates within the box of their
  // neighbours' (interpolating, never extrapolating past a chart's edge; as Wedges::merge).
  std::uint32_t j = 0;
  for (std::size_t i : fit) {
    VertexAttribute& to = out.attributes[i];
    std::vector<double> fresh = to.values;
    for (std::size_t v = 0; v < n; ++v) {
      if (unknown[v] < 0) continue;
      double* o = &fresh[v * to.components];
      for (std::uint32_t k = 0; k < to.components; ++k) o[k] = x(unknown[v], j + k);
      if (to.kind == AttributeKind::Normal && to.components == 3) {
        const double len = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
        if (len > 0) {
          for (int k = 0; k < 3; ++k) o[k] /= len;
        } else {
          std::copy_n(&to.values[v * 3], 3, o);
        }
      } else if (to.kind == AttributeKind::Color) {
        for (std::uint32_t k = 0; k < to.components; ++k) o[k] = std::clamp(o[k], 0.0, 1.0);
      } else if (to.kind == AttributeKind::TexCoord) {
        for (std::uint32_t k = 0; k < to.components; ++k) {
          double low = std::numeric_limits<double>::infinity(), high = -low;
          for (std::uint32_t a = start[v]; a < start[v + 1]; ++a)
            for (int q = 0; q < 3; ++q) {
              const std::uint32_t u = out.indices[3 * std::size_t(around[a]) + q];
              if (u == v) continue;
              low = std::min(low, to.values[std::size_t(u) * to.components + k]);
              high = std::max(high, to.values[std::size_t(u) * to.components + k]);
            }
          if (low <= high) o[k] = std::clamp(o[k], low, high);
        }
      }
    }
    to.values = std::move(fresh);
    j += to.components;
  }
}

}  // namespace qem::refit_detail
