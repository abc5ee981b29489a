// Bounding volume hierarchy (axis-aligned boxes) over triangles, for exact closest-point queries.
// Built as a linear BVH (Lauterbach et al. 2009, "Fast BVH construction on GPUs"): triangles sorted
// by the Morton code of their centres (a radix sort), each range split where its codes' highest
// differing bit turns on, boxes filled bottom up; linear time, a fraction of the binned
// surface-area-heuristic build it replaces, for the same answers (queries break ties by triangle
// index, never by the tree's layout). Nodes, boxes and triangles live in flat arrays, children of
// a node are adjacent, and triangles are stored in leaf order so a leaf reads contiguous memory:
// their nine coordinates, or, for a tree of an indexed mesh, their three vertex indices.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "core/default_init_allocator.h"
#include "geometry/vec3.h"

namespace qem::measure_detail {

/// Queries per work item, and per warm-started run: fixed, so results never depend on the threads.
inline constexpr std::size_t kQueryChunk = 4096;

class TriangleBvh {
 public:
  struct Hit {
    double d2 = std::numeric_limits<double>::infinity();  ///< squared distance
    std::uint32_t triangle = UINT32_MAX;                  ///< index into the build input
    double point[3] = {0, 0, 0};                          ///< closest point
  };

  TriangleBvh() = default;
  /// `corners`: 9 doubles per triangle (a.xyz b.xyz c.xyz). Built on up to `threads` threads; the
  /// tree is the same on any number.
  explicit TriangleBvh(std::span<const double> corners, unsigned threads = 1);
  /// The same tree over an indexed mesh: `vertices` (3 doubles each, taken over by the tree) and
  /// `indices` (3 per triangle, each below the vertex count). The tree keeps the vertices and each
  /// triangle's three indices instead of its nine coordinates: a third of the memory on a closed
  /// mesh (a vertex per two faces), and a build that writes a third of the bytes. The answers are
  /// those of the first form given each triangle's corners.
  TriangleBvh(core::UnzeroedVector<double> vertices, std::span<const std::uint32_t> indices, unsigned threads = 1);

  /// The closest point of all triangles to `p` (of two as close, the one of lower index, so the
  /// answer does not depend on the tree's layout); none closer than sqrt(max_d2) -> Hit with d2 = inf.
  Hit closest(const double p[3], double max_d2 = std::numeric_limits<double>::infinity()) const;
  /// Same, warm-started: the distance to triangle `*hint` (e.g. the previous query's answer, or
  /// UINT32_MAX for none) bounds the search from the start, which prunes most of the tree when
  /// consecutive queries are near each other. `*hint` is set to the closest triangle found.
  Hit closest(const double p[3], std::uint32_t* hint) const;
  /// The closest point within sqrt(max_d2) (as closest(p, max_d2): the same answer), the search
  /// bounded from the start by triangle `hint`'s distance when it is within max_d2.
  Hit closest(const double p[3], double max_d2, std::uint32_t hint) const;

  /// The squared distance from `p` to (input) triangle `id`: the number closest() compares.
  double triangle_d2(const double p[3], std::uint32_t id) const {
    double point[3];
    return slot_d2(p, slot_of_[id], point);
  }

  /// Appends to `out` the (input) index of every triangle within sqrt(max_d2) of `p`, in no order.
  void within(const double p[3], double max_d2, std::vector<std::uint32_t>& out) const;

  /// The 9 coordinates of (input) triangle `id`.
  std::array<double, 9> triangle(std::uint32_t id) const {
    std::array<double, 9> out;
    corners_of_slot(slot_of_[id], out.data());
    return out;
  }

  std::size_t triangle_count() const { return ids_.size(); }
  std::size_t node_count() const { return nodes_.size(); }
  bool empty() const { return ids_.empty(); }

  // The box in floats, rounded outward: a search prunes by the box's distance, which may only be
  // smaller than the true one, so the answers are those of double boxes, from half the memory.
  // Two children (32 bytes each) are read together: slot 1 of nodes_ is left empty, so that every
  // pair starts at an even slot, one 64-byte line (nodes_ is so aligned).
  struct Node {
    float lo[3], hi[3];
    std::uint32_t first;  ///< leaf: first stored triangle; inner: left child (right child = first + 1)
    std::uint32_t count;  ///< triangles in a leaf; 0 for an inner node
  };
  static_assert(sizeof(Node) == 32);
  /// Node i (0: the root), for tests of the layout.
  const Node& node(std::size_t i) const { return nodes_[i]; }

 private:
  // `corners_of(t, out)`: triangle t's 9 coordinates; `indices`: 3 vertex indices per triangle
  // (into vertices_) for the indexed form, stored instead of the coordinates; nullptr otherwise.
  template <class CornersOf>
  void build(std::size_t count, const CornersOf& corners_of, const std::uint32_t* indices, unsigned threads);
  Hit search(const double p[3], double best, std::uint32_t best_slot) const;
  double slot_d2(const double p[3], std::uint32_t slot, double point[3]) const;
  /// The corners of the triangle stored at `slot`, as points.
  void corners_at(std::uint32_t slot, Vec3& a, Vec3& b, Vec3& c) const {
    if (corner_index_.empty()) {
      const double* t = &tris_[9 * std::size_t(slot)];
      a = {t[0], t[1], t[2]}, b = {t[3], t[4], t[5]}, c = {t[6], t[7], t[8]};
      return;
    }
    const std::uint32_t* i = &corner_index_[3 * std::size_t(slot)];
    const double *p = &vertices_[3 * std::size_t(i[0])], *q = &vertices_[3 * std::size_t(i[1])],
                 *r = &vertices_[3 * std::size_t(i[2])];
    a = {p[0], p[1], p[2]}, b = {q[0], q[1], q[2]}, c = {r[0], r[1], r[2]};
  }
  void corners_of_slot(std::uint32_t slot, double out[9]) const {
    Vec3 corner[3];
    corners_at(slot, corner[0], corner[1], corner[2]);
    for (int k = 0; k < 3; ++k) out[3 * k] = corner[k].x, out[3 * k + 1] = corner[k].y, out[3 * k + 2] = corner[k].z;
  }

  // Written whole by the build before any read: not zero-filled first.
  std::vector<Node, core::AlignedDefaultInitAllocator<Node, 64>> nodes_;
  // The triangles in leaf order: 9 coordinates each (tris_), or, for an indexed mesh, 3 indices
  // each (corner_index_, empty in the other form) into the vertices (vertices_).
  core::UnzeroedVector<double> tris_;
  core::UnzeroedVector<double> vertices_;
  core::UnzeroedVector<std::uint32_t> corner_index_;
  core::UnzeroedVector<std::uint32_t> ids_;      ///< input index of each stored triangle
  core::UnzeroedVector<std::uint32_t> slot_of_;  ///< stored position of each input triangle
};

}  // namespace qem::measure_detail
