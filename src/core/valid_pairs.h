// Valid pairs of GH97 §3.2: every edge, plus every pair of vertices closer than the threshold t.
#pragma once

#include <cstdint>
#include <span>
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
std::vector<Edge> unique_edges(std::span<const std::uint32_t> triangles, const VertexLists& vertex_faces,
                               std::size_t vertex_count);
/// The same from the triangle list alone (its face lists made here), for callers that have none.
std::vector<Edge> unique_edges(std::span<const std::uint32_t> triangles, std::size_t vertex_count);

/// The edges of unique_edges with `faces == 1` (in its order, counted as it counts them), found
/// only from the vertices flagged in `from` (a superset of their lower ends): a renewal's border
/// planes on a mesh whose border vertices are known need not list every edge.
std::vector<Edge> single_face_edges(std::span<const std::uint32_t> triangles, const VertexLists& vertex_faces,
                                    std::span<const std::uint8_t> from);

/// Per vertex of a triangle list, 1 where one of its edges has a single face: the ends of the edges
/// of unique_edges with `faces == 1`, without making the edge list (12 bytes an edge, all
/// fresh pages, on the serial path of a large run's repair). Each vertex is decided from its own
/// faces alone, so the vertices are split among `threads` with the same result on any count.
/// Every index must be below `vertex_count`.
std::vector<std::uint8_t> border_vertices(std::span<const std::uint32_t> triangles, std::size_t vertex_count,
                                          unsigned threads);

/// How many of its nearest vertices within t each vertex pairs with (see close_pairs).
inline constexpr std::size_t kMaxThresholdPairsPerVertex = 8;

/// Pairs (i < j) of `candidates` with |p_i - p_j| < t that are not edges (GH97 §3.2 rule 2), each
/// vertex pairing with at most its `max_per_vertex` nearest such vertices: GH97 warns that a large
/// t creates O(n^2) pairs; this keeps the closest ones, which are the ones aggregation needs, and
/// keeps time and memory linear for any t. Found with a k-d tree (nanoflann). Sorted, unique.
std::vector<std::pair<std::uint32_t, std::uint32_t>> close_pairs(const std::vector<Vec3>& positions,
                                                                 const std::vector<std::uint32_t>& candidates,
                                                                 double t, const std::vector<Edge>& edges,
                                                                 std::size_t max_per_vertex);

}  // namespace qem::core
