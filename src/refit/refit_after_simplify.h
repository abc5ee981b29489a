// The refit that follows a simplification (SimplifyOptions::refit_rounds), outside the core: it
// takes the core's output and its map of where each input vertex went.
#pragma once

#include "qem/refit.h"
#include "qem/simplify.h"

namespace qem {

/// The refit options `simplify` uses for `options`: the same rounds, points per vertex, border
/// lock, face turn limit and threads. `qem lod` refits each level with them, as `simplify` would.
RefitOptions refit_options_for(const SimplifyOptions& options);

}  // namespace qem
