// Vertices grouped by exact position. Where a mesh's vertices are wedges (qem/mesh.h) or the input
// never welded a seam or crack, the vertices of one position are one point of the surface: the
// core welds them (working_mesh.cpp), a partitioned run with attributes finds and locks a cut
// through a seam by them (partition/), and the far-place repair holds them (far_repair.cpp).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "qem/mesh.h"

namespace qem::core {

/// For each vertex of `vertices` (indices of xyz triples in `positions`), the lowest-numbered of
/// `vertices` at exactly the same position; 0xffffffff for the vertices not listed. Sorted in
/// chunks on `threads` threads and merged: the order compared is total (position, then index), so
/// the result does not depend on the thread count.
std::vector<std::uint32_t> first_at_same_position(std::span<const double> positions,
                                                  std::vector<std::uint32_t> vertices, unsigned threads);

/// The same for every vertex of `input`.
std::vector<std::uint32_t> first_at_same_position(MeshView input, unsigned threads);

}  // namespace qem::core
