#include "core/same_position.h"

#include <algorithm>
#include <array>
#include <numeric>

#include "core/parallel_chunks.h"

namespace qem::core {

std::vector<std::uint32_t> first_at_same_position(std::span<const double> positions,
                                                  std::vector<std::uint32_t> order, unsigned threads) {
  const std::size_t n = order.size();
  const auto at = [&](std::uint32_t v) {
    return std::array<double, 3>{positions[3 * std::size_t(v)], positions[3 * std::size_t(v) + 1],
                                 positions[3 * std::size_t(v) + 2]};
  };
  const auto before = [&](std::uint32_t a, std::uint32_t b) { return at(a) != at(b) ? at(a) < at(b) : a < b; };
  // Sorted runs of a fixed length, merged pairwise: a serial sort of a few million vertices was a
  // third of a second, the partitioned run's largest serial step.
  constexpr std::size_t kRun = std::size_t(1) << 18;
  for_chunks(n, kRun, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    std::sort(order.begin() + std::ptrdiff_t(begin), order.begin() + std::ptrdiff_t(end), before);
  });
  for (std::size_t width = kRun; width < n; width *= 2)
    for_chunks(n, 2 * width, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
      if (begin + width < end)
        std::inplace_merge(order.begin() + std::ptrdiff_t(begin), order.begin() + std::ptrdiff_t(begin + width),
                           order.begin() + std::ptrdiff_t(end), before);
    });
  std::vector<std::uint32_t> first(positions.size() / 3, 0xffffffffu);
  for (std::size_t i = 0; i < n; ++i)
    first[order[i]] = i > 0 && at(order[i]) == at(order[i - 1]) ? first[order[i - 1]] : order[i];
  return first;
}

std::vector<std::uint32_t> first_at_same_position(MeshView input, unsigned threads) {
  std::vector<std::uint32_t> all(input.vertex_count());
  std::iota(all.begin(), all.end(), 0u);
  return first_at_same_position(input.positions, std::move(all), threads);
}

}  // namespace qem::core
