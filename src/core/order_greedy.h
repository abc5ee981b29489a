// GH97 §4's order of contractions: every pair in a heap keyed by its cost; repeatedly contract the
// cheapest. Exactly the paper's greedy order.
#pragma once

#include "core/context.h"

namespace qem::core {

/// Contracts until the settings' stop criteria are met or nothing is left; the vertex lists must
/// be exact when it starts (it keeps them exact).
void run_greedy(Context& c);

}  // namespace qem::core
