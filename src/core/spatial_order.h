// Renumbering vertices along a Morton (Z-order) curve, so that vertices close in space are close
// in memory. The contraction loop touches a vertex's neighbours, their quadrics, faces and pairs;
// with an arbitrary input order (e.g. subdivision order) each of those is a cache miss.
#pragma once

#include <cstdint>
#include <vector>

#include "core/quadric.h"

namespace qem::core {

/// The ids of `vertices` sorted along a Morton curve over their bounding box; ties keep input order.
std::vector<std::uint32_t> morton_order(const std::vector<Vec3>& positions, const std::vector<std::uint32_t>& vertices);

}  // namespace qem::core
