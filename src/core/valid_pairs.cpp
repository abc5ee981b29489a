#include "core/valid_pairs.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <nanoflann.hpp>

#include "core/faces_at_vertices.h"
#include "core/parallel_chunks.h"
#include "core/small_sort.h"
#include "qem/error.h"

namespace qem::core {

std::vector<Edge> unique_edges(std::span<const std::uint32_t> triangles, const VertexLists& vertex_faces,
                               std::size_t vertex_count) {
  std::vector<Edge> edges;
  // 3F/2 edges on a closed manifold, more with borders (up to 3F): the bound is reserved, since a
  // reallocation near the end would copy every edge into fresh pages (a page fault per 4 KiB, a
  // tenth of a small mesh's run on virtual machines), while reserved pages never written cost
  // no memory.
  edges.reserve(triangles.size() + 16);
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
    // By the upper end, each upper end once (so any sort gives this order).
    sort_small(edges.begin() + first, edges.end(), [](const Edge& a, const Edge& b) { return a.hi < b.hi; });
  }
  return edges;
}

std::vector<Edge> single_face_edges(std::span<const std::uint32_t> triangles, const VertexLists& vertex_faces,
                                    std::span<const std::uint8_t> from) {
  std::vector<Edge> edges, here;
  for (std::uint32_t v = 0; v < from.size(); ++v) {
    if (!from[v]) continue;
    here.clear();
    for (std::uint32_t f : vertex_faces[v])
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t w = triangles[3 * std::size_t(f) + k];
        if (w <= v) continue;  // from its lower end, as unique_edges
        auto it = std::find_if(here.begin(), here.end(), [w](const Edge& e) { return e.hi == w; });
        if (it == here.end())
          here.push_back({v, w, 1});
        else
          ++it->faces;
      }
    sort_small(here.begin(), here.end(), [](const Edge& a, const Edge& b) { return a.hi < b.hi; });
    for (const Edge& e : here)
      if (e.faces == 1) edges.push_back(e);
  }
  return edges;
}

std::vector<Edge> unique_edges(std::span<const std::uint32_t> triangles, std::size_t vertex_count) {
  VertexLists faces;
  faces.rebuild(vertex_count, [&](auto emit) {
    for (std::size_t c = 0; c < triangles.size(); ++c) emit(triangles[c], std::uint32_t(c / 3));
  });
  return unique_edges(triangles, faces, vertex_count);
}

std::vector<std::uint8_t> border_vertices(std::span<const std::uint32_t> triangles, std::size_t vertex_count,
                                          unsigned threads) {
  const FacesAtVertices faces = faces_at_vertices(triangles, vertex_count, threads);
  std::vector<std::uint8_t> border(vertex_count);
  constexpr std::size_t kChunk = std::size_t(1) << 14;
  for_chunks(vertex_count, kChunk, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    // v's neighbours and how many faces each: in arrays on the stack for an ordinary vertex (the
    // lookups are most of the work), in a vector round a large fan's hub.
    constexpr std::size_t kSmall = 64;
    std::uint32_t other[kSmall], count[kSmall];
    std::vector<std::pair<std::uint32_t, std::uint32_t>> many;
    for (std::size_t v = begin; v < end; ++v) {
      const auto at = faces.at(v);
      // A face listed k times at v (k corners at v) counts each other corner k times, as
      // unique_edges counts it from the edge's lower end.
      if (2 * at.size() <= kSmall) {
        std::size_t n = 0;
        for (std::uint32_t f : at)
          for (int k = 0; k < 3; ++k) {
            const std::uint32_t w = triangles[3 * std::size_t(f) + k];
            if (w == v) continue;
            std::size_t i = 0;
            while (i < n && other[i] != w) ++i;
            if (i == n) other[n] = w, count[n++] = 0;
            ++count[i];
          }
        border[v] = std::find(count, count + n, 1u) != count + n;
        continue;
      }
      many.clear();
      for (std::uint32_t f : at)
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t w = triangles[3 * std::size_t(f) + k];
          if (w == v) continue;
          auto it = std::find_if(many.begin(), many.end(), [w](const auto& o) { return o.first == w; });
          if (it == many.end())
            many.push_back({w, 1});
          else
            ++it->second;
        }
      border[v] = std::any_of(many.begin(), many.end(), [](const auto& o) { return o.second == 1; });
    }
  });
  return border;
}

namespace {
// nanoflann's view of the candidate points.
struct PointCloud {
  const std::vector<Vec3>& positions;
  const std::vector<std::uint32_t>& ids;
  std::size_t kdtree_get_point_count() const { return ids.size(); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const { return positions[ids[i]][int(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }
};
using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloud>, PointCloud, 3, std::uint32_t>;
}  // namespace

std::vector<std::pair<std::uint32_t, std::uint32_t>> close_pairs(const std::vector<Vec3>& positions,
                                                                 const std::vector<std::uint32_t>& candidates,
                                                                 double t, const std::vector<Edge>& edges,
                                                                 std::size_t max_per_vertex) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  if (!(t > 0) || candidates.size() < 2 || max_per_vertex == 0) return out;
  PointCloud cloud{positions, candidates};
  KdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  auto is_edge = [&](std::uint32_t a, std::uint32_t b) {
    auto it = std::lower_bound(edges.begin(), edges.end(), std::make_pair(a, b), [](const Edge& e, auto ab) {
      return e.lo < ab.first || (e.lo == ab.first && e.hi < ab.second);
    });
    return it != edges.end() && it->lo == a && it->hi == b;
  };
  // Ask for more than needed: edge neighbours are among the nearest and do not count.
  const std::size_t ask = std::min(candidates.size(), 2 * std::min(max_per_vertex, candidates.size()) + 8);
  std::vector<std::uint32_t> found(ask);
  std::vector<double> dist2(ask);
  std::vector<std::pair<double, std::uint32_t>> near;
  const double t2 = t * t;
  for (std::uint32_t v : candidates) {
    const double query[3] = {positions[v].x, positions[v].y, positions[v].z};
    const std::size_t n = tree.knnSearch(query, ask, found.data(), dist2.data());
    near.clear();
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t w = candidates[found[i]];
      if (w == v || !(dist2[i] < t2)) continue;
      if (is_edge(std::min(v, w), std::max(v, w))) continue;
      near.push_back({dist2[i], w});
    }
    // Nearest first, ties by id: the choice does not depend on the tree's traversal order.
    std::sort(near.begin(), near.end());
    if (near.size() > max_per_vertex) near.resize(max_per_vertex);
    for (auto [d, w] : near) out.push_back({std::min(v, w), std::max(v, w)});
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace qem::core
