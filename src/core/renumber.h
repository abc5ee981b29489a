// Dense renumbering between passes: once half the vertices are gone, the survivors, live faces and
// live pairs are numbered densely again, each in its old order, so later passes sweep small dense
// arrays instead of sparse ones (fewer cache misses per contraction). Every relative order is
// kept (tie-breaks on ids, the order of the rebuilt lists, output order), so the result is exactly
// the same. Each owner squeezes its own arrays; the vertex lists are rebuilt after it.
#pragma once

#include "core/context.h"
#include "core/order_passes.h"

namespace qem::core {

void renumber_densely(Context& c, PassState& s);

}  // namespace qem::core
