#include "measure/bvh.h"

#include <algorithm>
#include <cmath>

#include "measure/point_triangle.h"

namespace qem::measure_detail {

namespace {

constexpr int kBins = 16;          // SAH bins per split: 8-32 give the same tree quality (Wald 2007)
constexpr std::uint32_t kLeaf = 4;  // triangles per leaf at most
// Below this depth splits switch from SAH (which may peel off a few triangles per level on skewed
// inputs) to object medians, so the depth stays below kSahDepth + 32 and fits the query stack.
constexpr std::uint32_t kSahDepth = 48;
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
  double half_area() const {
    const double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
    return dx < 0 ? 0 : dx * dy + dy * dz + dz * dx;
  }
};

// Squared distance from p to an axis-aligned box (0 inside).
inline double box_d2(const double* p, const double* lo, const double* hi) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max(std::max(lo[k] - p[k], p[k] - hi[k]), 0.0);
    d2 += d * d;
  }
  return d2;
}

}  // namespace

TriangleBvh::TriangleBvh(const std::vector<double>& corners) {
  const std::uint32_t n = std::uint32_t(corners.size() / 9);
  if (n == 0) return;
  std::vector<Bounds> box(n);
  std::vector<double> centroid(3 * std::size_t(n));
  for (std::uint32_t t = 0; t < n; ++t) {
    for (int c = 0; c < 3; ++c) box[t].grow(&corners[9 * std::size_t(t) + 3 * c]);
    for (int k = 0; k < 3; ++k) centroid[3 * t + k] = 0.5 * (box[t].lo[k] + box[t].hi[k]);
  }
  std::vector<std::uint32_t> order(n);
  for (std::uint32_t t = 0; t < n; ++t) order[t] = t;

  nodes_.reserve(2 * std::size_t(n) / kLeaf + 1);
  nodes_.push_back({});
  struct Task {
    std::uint32_t node, begin, end, depth;
  };
  std::vector<Task> stack{{0, 0, n, 0}};
  while (!stack.empty()) {
    const Task task = stack.back();
    stack.pop_back();
    Bounds bounds, cbounds;
    for (std::uint32_t i = task.begin; i < task.end; ++i) {
      bounds.grow(box[order[i]]);
      cbounds.grow(&centroid[3 * order[i]]);
    }
    Node& node = nodes_[task.node];
    for (int k = 0; k < 3; ++k) node.lo[k] = bounds.lo[k], node.hi[k] = bounds.hi[k];
    node.first = task.begin;
    node.count = task.end - task.begin;
    if (node.count <= kLeaf) continue;

    // Binned SAH on the axis of largest centroid extent.
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (cbounds.hi[k] - cbounds.lo[k] > cbounds.hi[axis] - cbounds.lo[axis]) axis = k;
    const double extent = cbounds.hi[axis] - cbounds.lo[axis];
    std::uint32_t mid;
    if (!(extent > 0)) {
      // All centroids coincide: no plane separates them; halve by index to keep leaves small.
      mid = task.begin + (task.end - task.begin) / 2;
    } else if (task.depth >= kSahDepth) {
      mid = task.begin + (task.end - task.begin) / 2;
      std::nth_element(order.begin() + task.begin, order.begin() + mid, order.begin() + task.end,
                       [&](std::uint32_t a, std::uint32_t b) {
                         return centroid[3 * a + axis] < centroid[3 * b + axis] ||
                                (centroid[3 * a + axis] == centroid[3 * b + axis] && a < b);
                       });
    } else {
      const double scale = kBins / extent;
      auto bin_of = [&](std::uint32_t t) {
        return std::min(kBins - 1, int((centroid[3 * t + axis] - cbounds.lo[axis]) * scale));
      };
      Bounds bin_box[kBins];
      std::uint32_t bin_count[kBins] = {};
      for (std::uint32_t i = task.begin; i < task.end; ++i) {
        const int b = bin_of(order[i]);
        bin_box[b].grow(box[order[i]]);
        ++bin_count[b];
      }
      // Sweep from the right for the suffix costs, then from the left to pick the cheapest plane.
      double right_cost[kBins];
      Bounds acc;
      std::uint32_t cnt = 0;
      for (int b = kBins - 1; b > 0; --b) {
        acc.grow(bin_box[b]);
        cnt += bin_count[b];
        right_cost[b] = cnt ? acc.half_area() * cnt : 0;
      }
      acc = Bounds{};
      cnt = 0;
      int best = -1;
      double best_cost = INFINITY;
      for (int b = 0; b < kBins - 1; ++b) {
        acc.grow(bin_box[b]);
        cnt += bin_count[b];
        const double cost = (cnt ? acc.half_area() * cnt : 0) + right_cost[b + 1];
        if (cost < best_cost) best_cost = cost, best = b;
      }
      auto it = std::partition(order.begin() + task.begin, order.begin() + task.end,
                               [&](std::uint32_t t) { return bin_of(t) <= best; });
      mid = std::uint32_t(it - order.begin());
      if (mid == task.begin || mid == task.end) mid = task.begin + (task.end - task.begin) / 2;
    }
    const std::uint32_t left = std::uint32_t(nodes_.size());
    nodes_.push_back({});
    nodes_.push_back({});
    nodes_[task.node].first = left;  // `node` may dangle after push_back: index again
    nodes_[task.node].count = 0;
    stack.push_back({left + 1, mid, task.end, task.depth + 1});
    stack.push_back({left, task.begin, mid, task.depth + 1});
  }

  tris_.resize(9 * std::size_t(n));
  ids_ = std::move(order);
  for (std::uint32_t i = 0; i < n; ++i)
    std::copy_n(&corners[9 * std::size_t(ids_[i])], 9, &tris_[9 * std::size_t(i)]);
}

TriangleBvh::Hit TriangleBvh::closest(const double p[3], double max_d2) const {
  Hit hit;
  if (nodes_.empty()) return hit;
  double best = max_d2;
  std::uint32_t best_tri = UINT32_MAX;
  Vec3 best_point{0, 0, 0};
  const Vec3 q{p[0], p[1], p[2]};
  struct Entry {
    std::uint32_t node;
    double d2;
  };
  Entry stack[kStack];  // holds at most depth + 1 entries; the build bounds the depth (kSahDepth)
  int top = 0;
  stack[top++] = {0, box_d2(p, nodes_[0].lo, nodes_[0].hi)};
  while (top > 0) {
    const Entry e = stack[--top];
    if (e.d2 >= best) continue;
    const Node& node = nodes_[e.node];
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        const double* t = &tris_[9 * std::size_t(i)];
        const Vec3 c = closest_point_on_triangle(q, {t[0], t[1], t[2]}, {t[3], t[4], t[5]}, {t[6], t[7], t[8]});
        const double d2 = squared_distance(q, c);
        if (d2 < best) best = d2, best_tri = i, best_point = c;
      }
      continue;
    }
    const Node& l = nodes_[node.first];
    const Node& r = nodes_[node.first + 1];
    const double dl = box_d2(p, l.lo, l.hi), dr = box_d2(p, r.lo, r.hi);
    // Push the farther child first so the nearer one is searched first and tightens `best`.
    if (dl <= dr) {
      if (dr < best) stack[top++] = {node.first + 1, dr};
      if (dl < best) stack[top++] = {node.first, dl};
    } else {
      if (dl < best) stack[top++] = {node.first, dl};
      if (dr < best) stack[top++] = {node.first + 1, dr};
    }
  }
  if (best_tri != UINT32_MAX) {
    hit.d2 = best;
    hit.triangle = ids_[best_tri];
    hit.point[0] = best_point.x, hit.point[1] = best_point.y, hit.point[2] = best_point.z;
  }
  return hit;
}

}  // namespace qem::measure_detail
