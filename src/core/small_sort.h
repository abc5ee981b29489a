// Sorting the short runs of the set-up (a vertex's faces, its edges to higher vertices): a few
// elements each, where an insertion sort beats std::sort's set-up; a fan's hub (a triangulated
// n-gon) may hold millions, so a long run goes to std::sort and stays n log n.
#pragma once

#include <algorithm>
#include <cstddef>
#include <utility>

namespace qem::core {

/// Sorts [first, last) by `less` (not stably: callers' keys are distinct).
template <class It, class Less>
void sort_small(It first, It last, Less less) {
  constexpr std::ptrdiff_t kInsertionSortMax = 32;
  if (last - first > kInsertionSortMax) {
    std::sort(first, last, less);
    return;
  }
  for (It k = first; k != last; ++k)
    for (It j = k; j != first && less(*j, *(j - 1)); --j) std::swap(*j, *(j - 1));
}

}  // namespace qem::core
