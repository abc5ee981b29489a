// The faces around each vertex, in compressed rows: one counting sort over the corners.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>

#include "core/default_init_allocator.h"
#include "core/parallel_chunks.h"

namespace qem::core {

/// Per vertex v, the faces with a corner at v, in corner order (a face once per corner it has
/// at v): faces[start[v] .. start[v + 1]).
struct FacesAtVertices {
  UnzeroedVector<std::uint32_t> start;
  UnzeroedVector<std::uint32_t> faces;
  std::span<const std::uint32_t> at(std::size_t v) const {
    return {faces.data() + start[v], start[v + 1] - start[v]};
  }
};

/// The rows of `triangles` (3 indices a face, each below `vertex_count`; a trailing partial face
/// is ignored). The counts and the fill run in corner order on the calling thread; the arrays'
/// pages are first touched on `threads` (on a ten-million-face input those faults were most of
/// the work). Throws std::length_error beyond 32-bit offsets.
inline FacesAtVertices faces_at_vertices(std::span<const std::uint32_t> triangles, std::size_t vertex_count,
                                         unsigned threads) {
  const std::size_t corners = triangles.size() - triangles.size() % 3;
  if (corners >= 0xffffffffu) throw std::length_error("faces_at_vertices: face lists beyond 32-bit offsets");
  FacesAtVertices rows;
  rows.start = filled(vertex_count + 1, std::uint32_t(0), threads);
  for (std::size_t c = 0; c < corners; ++c) ++rows.start[triangles[c] + 1];
  for (std::size_t v = 0; v < vertex_count; ++v) rows.start[v + 1] += rows.start[v];
  UnzeroedVector<std::uint32_t> fill = filled(vertex_count, std::uint32_t(0), threads);
  rows.faces = filled(corners, std::uint32_t(0), threads);
  for (std::size_t c = 0; c < corners; ++c) {
    const std::uint32_t v = triangles[c];
    rows.faces[rows.start[v] + fill[v]++] = std::uint32_t(c / 3);
  }
  return rows;
}

}  // namespace qem::core
