#include "core/valid_pairs.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "qem/error.h"

namespace qem::core {

std::vector<Edge> unique_edges(const std::vector<std::uint32_t>& triangles, const VertexLists& vertex_faces,
                               std::size_t vertex_count) {
  std::vector<Edge> edges;
  edges.reserve(triangles.size() / 2 + 16);  // 3F/2 edges on a closed manifold
  std::vector<std::uint32_t> slot(vertex_count, 0xffffffffu);  // edge index of (v, w) while at v
  for (std::uint32_t v = 0; v < vertex_count; ++v) {
    const std::size_t first = edges.size();
    for (std::uint32_t f : vertex_faces[v]) {
      const std::uint32_t* t = &triangles[3 * std::size_t(f)];
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t w = t[k];
        if (w <= v) continue;  // each edge is found from its lower end
        if (slot[w] != 0xffffffffu && slot[w] >= first) {
          ++edges[slot[w]].faces;
        } else {
          slot[w] = std::uint32_t(edges.size());
          edges.push_back({v, w, 1});
        }
      }
    }
    std::sort(edges.begin() + first, edges.end(), [](const Edge& a, const Edge& b) { return a.hi < b.hi; });
  }
  return edges;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> close_pairs(const std::vector<Vec3>& positions,
                                                                 const std::vector<std::uint32_t>& candidates,
                                                                 double t, const std::vector<Edge>& edges,
                                                                 std::size_t max_pairs) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  if (!(t > 0) || candidates.size() < 2) return out;
  Vec3 lo = positions[candidates[0]];
  for (std::uint32_t v : candidates) {
    const Vec3& p = positions[v];
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
  }
  // Cell coordinates are clamped to 21 bits so a key fits in 64 bits; with more cells than that
  // along an axis, far-apart points may share a cell, which costs time but never a missed pair.
  auto cell_of = [&](const Vec3& p, int axis) {
    double c = std::floor((p[axis] - lo[axis]) / t);
    return std::int64_t(std::clamp(c, 0.0, double((1 << 21) - 2)));
  };
  auto key_of = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return (std::uint64_t(x) << 42) | (std::uint64_t(y) << 21) | std::uint64_t(z);
  };
  std::vector<std::pair<std::uint64_t, std::uint32_t>> cells;
  cells.reserve(candidates.size());
  for (std::uint32_t v : candidates) {
    const Vec3& p = positions[v];
    cells.push_back({key_of(cell_of(p, 0), cell_of(p, 1), cell_of(p, 2)), v});
  }
  std::sort(cells.begin(), cells.end());
  const double t2 = t * t;
  for (const auto& [key, v] : cells) {
    const Vec3& p = positions[v];
    std::int64_t cx = cell_of(p, 0), cy = cell_of(p, 1), cz = cell_of(p, 2);
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          std::int64_t x = cx + dx, y = cy + dy, z = cz + dz;
          if (x < 0 || y < 0 || z < 0) continue;
          std::uint64_t k = key_of(x, y, z);
          auto it = std::lower_bound(cells.begin(), cells.end(), std::make_pair(k, std::uint32_t(0)));
          for (; it != cells.end() && it->first == k; ++it) {
            std::uint32_t w = it->second;
            if (w <= v) continue;  // each unordered pair once
            Vec3 d = positions[w] - p;
            if (dot(d, d) >= t2) continue;
            out.push_back({v, w});
            if (out.size() > 4 * max_pairs)
              throw Error("threshold t = " + std::to_string(t) +
                          " (relative to the bounding-box diagonal) pairs too many vertices (more than " +
                          std::to_string(max_pairs) + "); choose a smaller --threshold");
          }
        }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  // Drop pairs that are edges already (they are valid pairs by GH97 §3.2 rule 1).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> kept;
  kept.reserve(out.size());
  for (auto [a, b] : out) {
    auto it = std::lower_bound(edges.begin(), edges.end(), std::make_pair(a, b), [](const Edge& e, auto ab) {
      return e.lo < ab.first || (e.lo == ab.first && e.hi < ab.second);
    });
    if (it != edges.end() && it->lo == a && it->hi == b) continue;
    kept.push_back({a, b});
  }
  if (kept.size() > max_pairs)
    throw Error("threshold pairs too many vertices (" + std::to_string(kept.size()) + " pairs, limit " +
                std::to_string(max_pairs) + "); choose a smaller --threshold");
  return kept;
}

}  // namespace qem::core
