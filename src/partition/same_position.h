// The input's vertices grouped by position, for a partitioned run with attributes: there a vertex is
// a wedge (qem/mesh.h), and the wedges of one position are one point of the surface (the core welds
// them, core/working_mesh.cpp), so a cut through a seam must be found, and locked, by position.
#pragma once

#include <cstdint>
#include <vector>

#include "qem/mesh.h"

namespace qem::partition_detail {

/// For every vertex of `input`, the lowest-numbered vertex at exactly the same position (itself
/// when it is the first). Sorted in chunks on `threads` threads and merged: the order compared is
/// total (position, then index), so the result does not depend on the thread count.
std::vector<std::uint32_t> first_at_same_position(MeshView input, unsigned threads);

}  // namespace qem::partition_detail
