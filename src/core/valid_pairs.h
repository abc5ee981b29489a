// Valid pairs of GH97 §3.2: every edge, plus every pair of vertices closer than the threshold t.
#pragma once

#include <cstdint>
#include <vector>

#include "core/quadric.h"
#include "core/vertex_lists.h"

namespace qem::core {

/// An undirected edge (lo < hi) and how many faces use it.
struct Edge {
  std::uint32_t lo, hi;
  std::uint32_t faces;
};

/// The unique edges of a triangle list (3 indices per face), sorted by (lo, hi), found through the
/// per-vertex face lists (no global sort, no 64-bit key array: this runs on million-face meshes).
std::vector<Edge> unique_edges(const std::vector<std::uint32_t>& triangles, const VertexLists& vertex_faces,
                               std::size_t vertex_count);

/// Pairs (i < j) of `candidates` with |p_i - p_j| < t that are not edges, found with a uniform
/// grid of cell size t (never O(n^2) unless the points crowd into few cells). Sorted, unique.
/// Throws qem::Error if more than `max_pairs` pairs are found: t is too large for the model.
std::vector<std::pair<std::uint32_t, std::uint32_t>> close_pairs(const std::vector<Vec3>& positions,
                                                                 const std::vector<std::uint32_t>& candidates,
                                                                 double t, const std::vector<Edge>& edges,
                                                                 std::size_t max_pairs);

}  // namespace qem::core
