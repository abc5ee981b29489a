#include "measure/bvh.h"

#include <algorithm>
#include <cmath>

#include "measure/point_triangle.h"

namespace qem::measure_detail {

namespace {

constexpr int kBins = 16;           // SAH bins per split: 8-32 give the same tree quality (Wald 2007)
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
  // Build items are partitioned in place, so every pass over a node's range reads contiguous memory.
  struct Item {
    Bounds box;
    double centroid[3];
    std::uint32_t id;
  };
  std::vector<Item> items(n);
  Bounds root, root_c;
  for (std::uint32_t t = 0; t < n; ++t) {
    Item& it = items[t];
    for (int c = 0; c < 3; ++c) it.box.grow(&corners[9 * std::size_t(t) + 3 * c]);
    for (int k = 0; k < 3; ++k) it.centroid[k] = 0.5 * (it.box.lo[k] + it.box.hi[k]);
    it.id = t;
    root.grow(it.box);
    root_c.grow(it.centroid);
  }
  auto range_bounds = [&](std::uint32_t begin, std::uint32_t end, Bounds& box, Bounds& cbox) {
    box = cbox = Bounds{};
    for (std::uint32_t i = begin; i < end; ++i) box.grow(items[i].box), cbox.grow(items[i].centroid);
  };

  nodes_.reserve(2 * std::size_t(n) / kLeaf + 1);
  nodes_.push_back({});
  struct Task {
    std::uint32_t node, begin, end, depth;
    Bounds box, cbox;  ///< of the triangles and of their centroids, known from the parent's bins
  };
  std::vector<Task> stack{{0, 0, n, 0, root, root_c}};
  while (!stack.empty()) {
    const Task task = stack.back();
    stack.pop_back();
    const Bounds& cbounds = task.cbox;
    Node& node = nodes_[task.node];
    for (int k = 0; k < 3; ++k) node.lo[k] = task.box.lo[k], node.hi[k] = task.box.hi[k];
    node.first = task.begin;
    node.count = task.end - task.begin;
    if (node.count <= kLeaf) continue;

    // Binned SAH on the axis of largest centroid extent.
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (cbounds.hi[k] - cbounds.lo[k] > cbounds.hi[axis] - cbounds.lo[axis]) axis = k;
    const double extent = cbounds.hi[axis] - cbounds.lo[axis];
    std::uint32_t mid;
    Bounds lbox, lcbox, rbox, rcbox;
    bool bounds_known = false;
    if (!(extent > 0)) {
      // All centroids coincide: no plane separates them; halve by index to keep leaves small.
      mid = task.begin + (task.end - task.begin) / 2;
    } else if (task.depth >= kSahDepth) {
      mid = task.begin + (task.end - task.begin) / 2;
      std::nth_element(items.begin() + task.begin, items.begin() + mid, items.begin() + task.end,
                       [&](const Item& a, const Item& b) {
                         return a.centroid[axis] < b.centroid[axis] ||
                                (a.centroid[axis] == b.centroid[axis] && a.id < b.id);
                       });
    } else {
      const double scale = kBins / extent;
      auto bin_of = [&](const Item& it) {
        return std::min(kBins - 1, int((it.centroid[axis] - cbounds.lo[axis]) * scale));
      };
      Bounds bin_box[kBins], bin_cbox[kBins];
      std::uint32_t bin_count[kBins] = {};
      for (std::uint32_t i = task.begin; i < task.end; ++i) {
        const int b = bin_of(items[i]);
        bin_box[b].grow(items[i].box);
        bin_cbox[b].grow(items[i].centroid);
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
      auto it = std::partition(items.begin() + task.begin, items.begin() + task.end,
                               [&](const Item& item) { return bin_of(item) <= best; });
      mid = std::uint32_t(it - items.begin());
      if (mid == task.begin || mid == task.end) {
        mid = task.begin + (task.end - task.begin) / 2;
      } else {
        for (int b = 0; b < kBins; ++b) {
          (b <= best ? lbox : rbox).grow(bin_box[b]);
          (b <= best ? lcbox : rcbox).grow(bin_cbox[b]);
        }
        bounds_known = true;
      }
    }
    if (!bounds_known) {
      range_bounds(task.begin, mid, lbox, lcbox);
      range_bounds(mid, task.end, rbox, rcbox);
    }
    const std::uint32_t left = std::uint32_t(nodes_.size());
    nodes_.push_back({});
    nodes_.push_back({});
    nodes_[task.node].first = left;  // `node` may dangle after push_back: index again
    nodes_[task.node].count = 0;
    stack.push_back({left + 1, mid, task.end, task.depth + 1, rbox, rcbox});
    stack.push_back({left, task.begin, mid, task.depth + 1, lbox, lcbox});
  }

  tris_.resize(9 * std::size_t(n));
  ids_.resize(n);
  slot_of_.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    ids_[i] = items[i].id;
    std::copy_n(&corners[9 * std::size_t(ids_[i])], 9, &tris_[9 * std::size_t(i)]);
    slot_of_[ids_[i]] = i;
  }
}

double TriangleBvh::slot_d2(const double p[3], std::uint32_t slot, double point[3]) const {
  const double* t = &tris_[9 * std::size_t(slot)];
  const Vec3 q{p[0], p[1], p[2]};
  const Vec3 c = closest_point_on_triangle(q, {t[0], t[1], t[2]}, {t[3], t[4], t[5]}, {t[6], t[7], t[8]});
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
  Entry stack[kStack];  // holds at most depth + 1 entries; the build bounds the depth (kSahDepth)
  int top = 0;
  stack[top++] = {0, box_d2(p, nodes_[0].lo, nodes_[0].hi)};
  while (top > 0) {
    const Entry e = stack[--top];
    if (e.d2 > best) continue;  // (not >=: a face as close but of a lower index wins the tie)
    const Node& node = nodes_[e.node];
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        const double* t = &tris_[9 * std::size_t(i)];
        const Vec3 c =
            closest_point_on_triangle(q, {t[0], t[1], t[2]}, {t[3], t[4], t[5]}, {t[6], t[7], t[8]});
        const double d2 = squared_distance(q, c);
        if (d2 < best || (d2 == best && best_tri != UINT32_MAX && ids_[i] < ids_[best_tri]))
          best = d2, best_tri = i;
      }
      continue;
    }
    const Node& l = nodes_[node.first];
    const Node& r = nodes_[node.first + 1];
    const double dl = box_d2(p, l.lo, l.hi), dr = box_d2(p, r.lo, r.hi);
    // Push the farther child first so the nearer one is searched first and tightens `best`.
    if (dl <= dr) {
      if (dr <= best) stack[top++] = {node.first + 1, dr};
      if (dl <= best) stack[top++] = {node.first, dl};
    } else {
      if (dl <= best) stack[top++] = {node.first, dl};
      if (dr <= best) stack[top++] = {node.first + 1, dr};
    }
  }
  if (best_tri != UINT32_MAX) {
    // The closest point is recomputed once here rather than stored at every improvement.
    hit.d2 = slot_d2(p, best_tri, hit.point);
    hit.triangle = ids_[best_tri];
  }
  return hit;
}

}  // namespace qem::measure_detail
