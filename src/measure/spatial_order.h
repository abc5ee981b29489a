// Orders query points along a Morton (Z-order) curve, so that consecutive closest-point queries
// are near each other: the previous answer then bounds the next search tightly (TriangleBvh hint)
// and the tree nodes it touches are still in cache.
#pragma once

#include <cstdint>
#include <vector>

namespace qem::measure_detail {

/// Indices 0..n-1 of the points `xyz` (3 per point) sorted by Morton code over their bounding box;
/// ties by index, so the order is fully determined by the input.
std::vector<std::uint32_t> morton_order(const std::vector<double>& xyz);

}  // namespace qem::measure_detail
