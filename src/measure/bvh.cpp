#include "measure/bvh.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "core/parallel_chunks.h"
#include "core/radix_sort.h"
#include "core/spatial_order.h"
#include "measure/point_triangle.h"

namespace qem::measure_detail {

namespace {

constexpr std::uint32_t kLeaf = 4;     // triangles per leaf at most
constexpr std::uint32_t kGrid = 1024;  // Morton cells per axis: 30-bit codes
// Query stacks: a search holds at most depth + 1 entries, and the depth stays below 30 + 32.
constexpr int kStack = 128;

struct Bounds {
  double lo[3] = {INFINITY, INFINITY, INFINITY};
  double hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  void grow(const double* p) {
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  }
  void grow(const Bounds& b) {
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], b.lo[k]), hi[k] = std::max(hi[k], b.hi[k]);
  }
};

// Squared distance from p to an axis-aligned box (0 inside).
inline double box_d2(const double* p, const float* lo, const float* hi) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max(std::max(double(lo[k]) - p[k], p[k] - double(hi[k])), 0.0);
    d2 += d * d;
  }
  return d2;
}

// The float at or below x, and at or above it (outside float's range: the largest float or the
// infinity on that side; the conversion itself is only made within the range).
inline float float_below(double x) {
  constexpr float kMax = std::numeric_limits<float>::max(), kInf = std::numeric_limits<float>::infinity();
  if (std::isnan(x)) return std::numeric_limits<float>::quiet_NaN();
  if (x >= double(kMax)) return kMax;
  if (x < -double(kMax)) return -kInf;
  const float f = float(x);
  return double(f) > x ? std::nextafter(f, -kInf) : f;
}
inline float float_above(double x) { return -float_below(-x); }

}  // namespace

template <class CornersOf>
void TriangleBvh::build(std::size_t count, const CornersOf& corners_of, const std::uint32_t* indices,
                        unsigned threads) {
  const std::uint32_t n = std::uint32_t(count);
  if (n == 0) return;
  // Every step but the radix sort and the top-down split is per triangle (or per node) and runs
  // in fixed chunks on the threads: on a ten-million-face input the build was a serial stretch of
  // seconds beside parallel work. The chunks never change a result: per-chunk boxes are combined
  // by min and max, which are exact, so the tree is the same on any number of threads.
  constexpr std::size_t kChunk = std::size_t(1) << 16;
  const auto centre_of = [&](std::uint32_t t, double centre[3]) {  // of the triangle's box, as Bounds::grow makes it
    double c[9];
    corners_of(t, c);
    for (int k = 0; k < 3; ++k) {
      double lo = INFINITY, hi = -INFINITY;
      for (int i = 0; i < 3; ++i) lo = std::min(lo, c[3 * i + k]), hi = std::max(hi, c[3 * i + k]);
      centre[k] = 0.5 * (lo + hi);
    }
  };
  // The box of the triangles' box centres: the grid of the Morton codes.
  std::vector<Bounds> chunk_centres((n + kChunk - 1) / kChunk);
  core::for_chunks(n, kChunk, threads, [&](std::size_t chunk, std::size_t begin, std::size_t end) {
    Bounds b;
    for (std::size_t t = begin; t < end; ++t) {
      double centre[3];
      centre_of(std::uint32_t(t), centre);
      b.grow(centre);
    }
    chunk_centres[chunk] = b;
  });
  Bounds centres;
  for (const Bounds& b : chunk_centres) centres.grow(b);
  // Morton codes of the centres on a 1024^3 grid over their box (one scale for all axes: cubic
  // cells), triangles sorted by code, ties by index (a stable radix sort).
  const double extent =
      std::max({centres.hi[0] - centres.lo[0], centres.hi[1] - centres.lo[1], centres.hi[2] - centres.lo[2]});
  const double scale = extent > 0 ? double(kGrid - 1) / extent : 0;
  using Indices = core::UnzeroedVector<std::uint32_t>;
  Indices code(n), order(n), scratch;
  core::for_chunks(n, kChunk, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t) {
      std::uint32_t m = 0;
      double centre[3];
      centre_of(std::uint32_t(t), centre);
      for (int k = 0; k < 3; ++k) {
        // Clamped before the conversion: NaN and out-of-range doubles must never reach the cast.
        const double c = (centre[k] - centres.lo[k]) * scale;
        const std::uint64_t cell = c >= 0 ? std::uint64_t(std::min(c, double(kGrid - 1))) : 0;
        m |= std::uint32_t(core::spread_bits_3d(cell)) << k;
      }
      code[t] = m;
      order[t] = std::uint32_t(t);
    }
  });
  core::radix_sort_by_key(order, scratch, [&](std::uint32_t t) { return code[t]; }, threads);
  Indices().swap(scratch);
  Indices sorted_code(n);
  core::for_chunks(n, kChunk, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) sorted_code[i] = code[order[i]];
  });
  Indices().swap(code);

  // Top down: a range splits where its codes' highest differing bit turns on (a spatial median,
  // as in an octree); a range of equal codes splits in half. The depth stays below 30 + log2(n).
  const auto split_point = [&](std::uint32_t begin, std::uint32_t end) {
    const std::uint32_t lo_code = sorted_code[begin], hi_code = sorted_code[end - 1];
    if (lo_code == hi_code) return begin + (end - begin) / 2;
    const std::uint32_t bit = std::uint32_t(1) << (31 - std::countl_zero(lo_code ^ hi_code));
    // The codes share every bit above `bit`, so `bit` is off, then on, along the range.
    return std::uint32_t(std::partition_point(sorted_code.begin() + begin, sorted_code.begin() + end,
                                              [&](std::uint32_t c) { return (c & bit) == 0; }) -
                         sorted_code.begin());
  };
  // Nodes in depth-first order, left before right; an inner node's children are a pair at `first`
  // (even slots: slot 1 stays unused), written when the node is, so each subtree's pairs are one
  // run of slots. The ranges of at most kSubtree triangles are split on the threads (each into the
  // run of slots its subtree takes, counted first), the few above them here: serial, the split and
  // its first writes to the node array's fresh pages were seconds of a ten-million-face run. The
  // layout is the one a single depth-first pass makes, on any number of threads.
  // Room for the most nodes there can be: every leaf holds a triangle at least, so at most n
  // leaves and n - 1 inner nodes, and slot 1. Pages are taken as the nodes are written (about
  // 0.65 n of them on scanned meshes), and never copied to a larger array.
  constexpr std::uint32_t kSubtree = std::uint32_t(1) << 15;
  struct Subtree {
    std::uint32_t node = 0, begin = 0, end = 0, first = 0, pairs = 0;
  };
  std::vector<Subtree> subtrees;
  const auto find_subtrees = [&](auto&& self, std::uint32_t begin, std::uint32_t end) -> void {
    if (end - begin <= kSubtree) {
      subtrees.push_back({0, begin, end, 0, 0});
      return;
    }
    const std::uint32_t mid = split_point(begin, end);
    self(self, begin, mid);
    self(self, mid, end);
  };
  find_subtrees(find_subtrees, 0, n);
  const auto count_pairs = [&](auto&& self, std::uint32_t begin, std::uint32_t end) -> std::uint32_t {
    if (end - begin <= kLeaf) return 0;
    const std::uint32_t mid = split_point(begin, end);
    return 1 + self(self, begin, mid) + self(self, mid, end);
  };
  core::for_chunks(subtrees.size(), 1, threads, [&](std::size_t i, std::size_t, std::size_t) {
    subtrees[i].pairs = count_pairs(count_pairs, subtrees[i].begin, subtrees[i].end);
  });
  nodes_.resize(2 * std::size_t(n) + 1);
  nodes_[1] = {};  // slot 1, unused: pairs of children start at even slots
  std::uint32_t used = 2;
  std::vector<std::uint32_t> top_inner;  // the inner nodes above the subtrees, parents first
  std::size_t next_subtree = 0;
  const auto place = [&](auto&& self, std::uint32_t node, std::uint32_t begin, std::uint32_t end) -> void {
    if (end - begin <= kSubtree) {
      Subtree& t = subtrees[next_subtree++];
      t.node = node, t.first = used;
      used += 2 * t.pairs;
      return;
    }
    const std::uint32_t mid = split_point(begin, end), left = used;
    used += 2;
    nodes_[node] = {};
    nodes_[node].first = left;
    nodes_[node].count = 0;
    top_inner.push_back(node);
    self(self, left, begin, mid);
    self(self, left + 1, mid, end);
  };
  place(place, 0, 0, n);
  const auto write = [&](auto&& self, std::uint32_t node, std::uint32_t begin, std::uint32_t end,
                         std::uint32_t& next) -> void {
    nodes_[node] = {};
    nodes_[node].first = begin;
    nodes_[node].count = end - begin;
    if (end - begin <= kLeaf) return;
    const std::uint32_t mid = split_point(begin, end), left = next;
    next += 2;
    nodes_[node].first = left;
    nodes_[node].count = 0;
    self(self, left, begin, mid, next);
    self(self, left + 1, mid, end, next);
  };
  core::for_chunks(subtrees.size(), 1, threads, [&](std::size_t i, std::size_t, std::size_t) {
    std::uint32_t next = subtrees[i].first;
    write(write, subtrees[i].node, subtrees[i].begin, subtrees[i].end, next);
  });
  nodes_.resize(used);
  Indices().swap(sorted_code);
  // The triangles in leaf order, so that a leaf reads contiguous memory (here, for its box, too).
  if (indices)
    corner_index_.resize(3 * std::size_t(n));
  else
    tris_.resize(9 * std::size_t(n));
  slot_of_.resize(n);
  core::for_chunks(n, kChunk, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (indices)
        std::copy_n(&indices[3 * std::size_t(order[i])], 3, &corner_index_[3 * i]);
      else
        corners_of(order[i], &tris_[9 * i]);
      slot_of_[order[i]] = std::uint32_t(i);
    }
  });
  ids_ = std::move(order);
  // Boxes bottom up: the leaves' from their triangles (side by side), then each inner node's from
  // its children, which come after it in the array.
  const auto set_box = [](Node& node, const Bounds& b) {
    for (int k = 0; k < 3; ++k) node.lo[k] = float_below(b.lo[k]), node.hi[k] = float_above(b.hi[k]);
  };
  core::for_chunks(nodes_.size(), kChunk, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      Node& node = nodes_[i];
      if (node.count == 0) continue;
      Bounds b;
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
        double c[9];
        corners_of_slot(k, c);
        for (int j = 0; j < 3; ++j) b.grow(&c[3 * j]);
      }
      set_box(node, b);
    }
  });
  // Each subtree's run of slots from the end (children come after their parent), then its root,
  // on the threads; then the nodes above the subtrees, children first.
  const auto inner_box = [&](std::size_t i) {
    Node& node = nodes_[i];
    if (node.count > 0) return;
    const Node &l = nodes_[node.first], &r = nodes_[node.first + 1];
    for (int k = 0; k < 3; ++k) node.lo[k] = std::min(l.lo[k], r.lo[k]), node.hi[k] = std::max(l.hi[k], r.hi[k]);
  };
  core::for_chunks(subtrees.size(), 1, threads, [&](std::size_t t, std::size_t, std::size_t) {
    for (std::size_t i = subtrees[t].first + 2 * std::size_t(subtrees[t].pairs); i-- > subtrees[t].first;) inner_box(i);
    inner_box(subtrees[t].node);
  });
  for (std::size_t i = top_inner.size(); i-- > 0;) inner_box(top_inner[i]);
}

TriangleBvh::TriangleBvh(std::span<const double> corners, unsigned threads) {
  build(
      corners.size() / 9,
      [corners](std::uint32_t t, double* out) { std::copy_n(&corners[9 * std::size_t(t)], 9, out); }, nullptr,
      threads);
}

TriangleBvh::TriangleBvh(core::UnzeroedVector<double> vertices, std::span<const std::uint32_t> indices,
                         unsigned threads)
    : vertices_(std::move(vertices)) {
  build(
      indices.size() / 3,
      [&](std::uint32_t t, double* out) {
        for (int k = 0; k < 3; ++k) std::copy_n(&vertices_[3 * std::size_t(indices[3 * std::size_t(t) + k])], 3, &out[3 * k]);
      },
      indices.data(), threads);
}

double TriangleBvh::slot_d2(const double p[3], std::uint32_t slot, double point[3]) const {
  const Vec3 q{p[0], p[1], p[2]};
  Vec3 a, b, d;
  corners_at(slot, a, b, d);
  const Vec3 c = closest_point_on_triangle(q, a, b, d);
  point[0] = c.x, point[1] = c.y, point[2] = c.z;
  return squared_distance(q, c);
}

TriangleBvh::Hit TriangleBvh::closest(const double p[3], double max_d2) const {
  return search(p, max_d2, UINT32_MAX);
}

TriangleBvh::Hit TriangleBvh::closest(const double p[3], std::uint32_t* hint) const {
  if (ids_.empty()) return Hit{};
  double best = std::numeric_limits<double>::infinity();
  std::uint32_t slot = UINT32_MAX;
  if (*hint < ids_.size()) {
    double point[3];
    slot = slot_of_[*hint];
    best = slot_d2(p, slot, point);
  }
  const Hit hit = search(p, best, slot);
  *hint = hit.triangle;
  return hit;
}

TriangleBvh::Hit TriangleBvh::closest(const double p[3], double max_d2, std::uint32_t hint) const {
  if (hint >= ids_.size()) return search(p, max_d2, UINT32_MAX);
  double point[3];
  const std::uint32_t slot = slot_of_[hint];
  const double d2 = slot_d2(p, slot, point);
  return d2 <= max_d2 ? search(p, d2, slot) : search(p, max_d2, UINT32_MAX);
}

void TriangleBvh::within(const double p[3], double max_d2, std::vector<std::uint32_t>& out) const {
  if (nodes_.empty()) return;
  std::uint32_t stack[kStack];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (box_d2(p, node.lo, node.hi) > max_d2) continue;
    if (node.count == 0) {
      stack[top++] = node.first;
      stack[top++] = node.first + 1;
      continue;
    }
    double point[3];
    for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
      if (slot_d2(p, i, point) <= max_d2) out.push_back(ids_[i]);
  }
}

TriangleBvh::Hit TriangleBvh::search(const double p[3], double best, std::uint32_t best_tri) const {
  Hit hit;
  if (nodes_.empty()) return hit;
  const Vec3 q{p[0], p[1], p[2]};
  struct Entry {
    std::uint32_t node;
    double d2;
  };
  Entry stack[kStack];  // at most one entry a level (a node's farther child): the build bounds the depth
  int top = 0;
  // The nearer child of a node is searched next without going through the stack; the farther
  // waits there.
  std::uint32_t at = 0;
  if (box_d2(p, nodes_[0].lo, nodes_[0].hi) > best) at = UINT32_MAX;
  for (;;) {
    if (at == UINT32_MAX) {
      if (top == 0) break;
      const Entry e = stack[--top];
      if (e.d2 > best) continue;  // (not >=: a face as close but of a lower index wins the tie)
      at = e.node;
    }
    const Node& node = nodes_[at];
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        Vec3 a, b, d;
        corners_at(i, a, b, d);
        const Vec3 c = closest_point_on_triangle(q, a, b, d);
        const double d2 = squared_distance(q, c);
        if (d2 < best || (d2 == best && best_tri != UINT32_MAX && ids_[i] < ids_[best_tri]))
          best = d2, best_tri = i;
      }
      at = UINT32_MAX;
      continue;
    }
    const Node& l = nodes_[node.first];
    const Node& r = nodes_[node.first + 1];
    const double dl = box_d2(p, l.lo, l.hi), dr = box_d2(p, r.lo, r.hi);
    const bool left_first = dl <= dr;
    const double d_near = left_first ? dl : dr, d_far = left_first ? dr : dl;
    const std::uint32_t near = left_first ? node.first : node.first + 1;
    if (d_far <= best) stack[top++] = {left_first ? node.first + 1 : node.first, d_far};
    at = d_near <= best ? near : UINT32_MAX;
  }
  if (best_tri != UINT32_MAX) {
    // The closest point is recomputed once here rather than stored at every improvement.
    hit.d2 = slot_d2(p, best_tri, hit.point);
    hit.triangle = ids_[best_tri];
  }
  return hit;
}

}  // namespace qem::measure_detail
