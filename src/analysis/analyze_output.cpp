// The pictures of GH97: error-quadric ellipsoids (Fig. 11, Fig. 18) and valid pairs (Fig. 19).
#include <algorithm>
#include <cmath>
#include <string>

#include "core/quadric.h"
#include "core/valid_pairs.h"
#include "geometry/vec3.h"
#include "io/io_common.h"
#include "qem/analyze.h"
#include "qem/error.h"

namespace qem {

namespace {

/// The unit sphere as an octahedron subdivided once and projected (18 vertices, 32 faces): enough
/// to read an ellipsoid's axes, small enough for one per vertex of a 100k-vertex mesh.
void unit_sphere(std::vector<double>& pos, std::vector<std::uint32_t>& tri) {
  const double oct[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const int faces[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                           {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  pos.assign(&oct[0][0], &oct[0][0] + 18);
  auto midpoint = [&](int a, int b) {
    // Edge midpoints are shared by two faces: look them up so the sphere is closed.
    double m[3];
    for (int k = 0; k < 3; ++k) m[k] = pos[3 * a + k] + pos[3 * b + k];
    double len = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    for (int k = 0; k < 3; ++k) m[k] /= len;
    for (std::size_t v = 0; v < pos.size() / 3; ++v)
      if (std::abs(pos[3 * v] - m[0]) + std::abs(pos[3 * v + 1] - m[1]) + std::abs(pos[3 * v + 2] - m[2]) <
          1e-12)
        return std::uint32_t(v);
    pos.insert(pos.end(), m, m + 3);
    return std::uint32_t(pos.size() / 3 - 1);
  };
  tri.clear();
  for (const auto& f : faces) {
    std::uint32_t a = f[0], b = f[1], c = f[2];
    std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
    std::uint32_t sub[4][3] = {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}};
    for (auto& s : sub) tri.insert(tri.end(), s, s + 3);
  }
}

}  // namespace

Mesh quadric_ellipsoids(const Mesh& mesh, const Analysis& analysis, double scale) {
  if (!(scale > 0) || !std::isfinite(scale))
    throw Error("ellipsoids: scale must be positive, got " + std::to_string(scale));
  // Mean edge length sets the picture's scale, so the ellipsoids look the same on any model size.
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t f = 0; f < mesh.face_count(); ++f)
    for (int j = 0; j < 3; ++j) {
      const double* a = &mesh.positions[3 * mesh.indices[3 * f + j]];
      const double* b = &mesh.positions[3 * mesh.indices[3 * f + (j + 1) % 3]];
      sum += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                       (a[2] - b[2]) * (a[2] - b[2]));
      ++count;
    }
  const double shortest = scale * 0.15 * (count ? sum / double(count) : 1);
  const double max_stretch = 6;

  std::vector<double> sp;
  std::vector<std::uint32_t> st;
  unit_sphere(sp, st);
  const std::size_t sv = sp.size() / 3;
  Mesh out;
  for (std::size_t v = 0; v < analysis.vertex_count(); ++v) {
    if (analysis.valence[v] == 0) continue;
    const double* lam = &analysis.eigenvalues[3 * v];
    const double* e = &analysis.eigenvectors[9 * v];
    // Level set x^T A x = eps: semi-axis_i = sqrt(eps / lambda_i); eps fixed per vertex so that the
    // normal axis (largest lambda) has length `shortest` (GH97 Fig. 11 draws one level per vertex).
    double r[3];
    for (int i = 0; i < 3; ++i) {
      double ratio = lam[i] > 0 ? std::sqrt(lam[2] / lam[i]) : max_stretch;
      r[i] = shortest * std::min(max_stretch, ratio);
    }
    std::uint32_t base = std::uint32_t(out.positions.size() / 3);
    for (std::size_t s = 0; s < sv; ++s)
      for (int k = 0; k < 3; ++k) {
        double x = mesh.positions[3 * v + k];
        for (int i = 0; i < 3; ++i) x += e[3 * i + k] * r[i] * sp[3 * s + i];
        out.positions.push_back(x);
      }
    for (std::uint32_t idx : st) out.indices.push_back(base + idx);
  }
  return out;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> valid_pairs(const Mesh& mesh, double threshold,
                                                                 std::size_t* edge_count) {
  std::size_t nv = mesh.vertex_count();
  for (std::size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= nv)
      throw Error("pairs: face " + std::to_string(i / 3) + " has an out-of-range vertex");
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  std::vector<bool> referenced(nv, false);
  for (std::size_t f = 0; f < mesh.face_count(); ++f)
    for (int j = 0; j < 3; ++j) {
      std::uint32_t a = mesh.indices[3 * f + j], b = mesh.indices[3 * f + (j + 1) % 3];
      referenced[a] = true;
      if (a != b) pairs.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  if (edge_count) *edge_count = pairs.size();
  if (threshold > 0) {
    std::vector<core::Edge> edges;
    edges.reserve(pairs.size());
    for (auto& [a, b] : pairs) edges.push_back({a, b, 1});
    std::vector<Vec3> pos(nv);
    for (std::size_t v = 0; v < nv; ++v)
      pos[v] = {mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]};
    std::vector<std::uint32_t> candidates;
    for (std::size_t v = 0; v < nv; ++v)
      if (referenced[v]) candidates.push_back(std::uint32_t(v));
    // No per-vertex cap: the picture shows every pair within t (the simplifier keeps the nearest).
    // The same pairs the simplifier uses (GH97 Fig. 19).
    auto close = core::close_pairs(pos, candidates, threshold, edges, core::kMaxThresholdPairsPerVertex);
    pairs.insert(pairs.end(), close.begin(), close.end());
  }
  return pairs;
}

void save_pairs_obj(const std::string& path, const Mesh& mesh,
                    const std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs, std::size_t edges) {
  std::string out = "# valid pairs (GH97 Fig. 19): group edges, then group non_edges\n";
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    out += "v";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      io::append_number(out, mesh.positions[3 * v + k]);
    }
    out += '\n';
  }
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (i == 0 && edges > 0) out += "g edges\n";
    if (i == edges) out += "g non_edges\n";
    out += "l ";
    io::append_uint(out, pairs[i].first + 1);
    out += ' ';
    io::append_uint(out, pairs[i].second + 1);
    out += '\n';
  }
  io::write_file_atomic(path, out);
}

}  // namespace qem
