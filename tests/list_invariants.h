// For the tests of the contraction orders: the vertex lists as a contraction reads them are the
// mesh's own.
#pragma once

#include "core/context.h"
#include "core/order_passes.h"

namespace qem::test {

/// Every vertex's lists, as they are read, hold exactly its live faces and its pairs that are not
/// dead; throws std::logic_error at the first that does not. In a pass (s.merged_from not empty)
/// a survivor's face list is never read again (it is not contracted twice) and a removed vertex's
/// lists are not read at all; otherwise every list must be exact. Walks the whole mesh: for small
/// meshes (core::RunHooks::after_band).
void check_vertex_lists(const core::Context& c, const core::PassState& s);

}  // namespace qem::test
