#include "core/valid_pairs.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "qem/error.h"

namespace qem::core {

namespace {
std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  return (std::uint64_t(a) << 32) | b;
}

// LSD radix sort on 64-bit keys, 16 bits a pass: the edge keys of a million-face mesh sort in a
// fraction of the time std::sort takes, and this runs once per simplification.
void radix_sort(std::vector<std::uint64_t>& keys) {
  std::vector<std::uint64_t> tmp(keys.size());
  std::uint64_t all_or = 0;
  for (std::uint64_t k : keys) all_or |= k;
  for (int shift = 0; shift < 64; shift += 16) {
    if (((all_or >> shift) & 0xffff) == 0) continue;  // digit is zero everywhere: nothing to do
    std::vector<std::size_t> count(65537, 0);
    for (std::uint64_t k : keys) ++count[((k >> shift) & 0xffff) + 1];
    for (std::size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
    for (std::uint64_t k : keys) tmp[count[(k >> shift) & 0xffff]++] = k;
    keys.swap(tmp);
  }
}
}  // namespace

std::vector<Edge> unique_edges(const std::vector<std::uint32_t>& triangles) {
  std::vector<std::uint64_t> keys;
  keys.reserve(triangles.size());
  for (std::size_t f = 0; f + 2 < triangles.size(); f += 3) {
    const std::uint32_t* t = &triangles[f];
    keys.push_back(edge_key(t[0], t[1]));
    keys.push_back(edge_key(t[1], t[2]));
    keys.push_back(edge_key(t[2], t[0]));
  }
  radix_sort(keys);
  std::vector<Edge> edges;
  edges.reserve(keys.size() / 2 + 16);
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i + 1;
    while (j < keys.size() && keys[j] == keys[i]) ++j;
    edges.push_back({std::uint32_t(keys[i] >> 32), std::uint32_t(keys[i]), std::uint32_t(j - i)});
    i = j;
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
