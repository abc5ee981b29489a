// The threads for_chunks and side_by_side run their work on (parallel_chunks.h): started once, on
// the first call that wants a helper, and kept for the rest of the process, so that a run's many
// short parallel steps (each band of a pass, each re-cost, each projection of the refit) do not
// each start and join threads of their own. A call's caller always works too and never waits for a
// helper that has not joined its job, so a call finishes even when every pool thread is busy
// elsewhere (nested calls, other callers): it then does all of the work itself.
#pragma once

#include <functional>

namespace qem::core {

/// Runs work(0) on the calling thread and work(1) .. work(helpers) on pool threads that are free
/// now or soon; returns once work(0) has returned and every work(k) that was started has
/// returned. Some work(k), k >= 1, may never be called: work must tolerate that (for_chunks's
/// workers share one queue of chunks, which the caller empties if no helper comes). work must not
/// throw.
void run_with_helpers(unsigned helpers, const std::function<void(unsigned)>& work);

}  // namespace qem::core
