// GH97 §4's order of contractions: every pair in a heap keyed by its cost; repeatedly contract the
// cheapest. Exactly the paper's greedy order.
#pragma once

#include <cstdint>
#include <vector>

#include "core/context.h"

namespace qem::core {

/// Contracts until the settings' stop criteria are met or nothing is left; the vertex lists must
/// be exact when it starts (it keeps them exact). `stale` (may be null: every cost is computed)
/// marks the pairs whose cost must be computed; the others' `pairs.cost` is taken as current.
/// `forget_at`: the face count of the next renewal of the quadrics (Settings::forget_due).
void run_greedy(Context& c, const std::vector<std::uint8_t>* stale, double forget_at);

}  // namespace qem::core
