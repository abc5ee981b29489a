// The refit that follows a simplification (SimplifyOptions::refit_rounds), outside the core: it
// takes the core's output and its map of where each input vertex went.
#pragma once

#include "qem/refit.h"
#include "qem/simplify.h"

namespace qem {

/// The refit options `simplify` uses for `options`: the same rounds, points per vertex, face turn
/// limit and threads; the border locked with lock_border or exact_border (a border vertex the
/// refit slid along a curved border would leave the input's polyline); an absolute max_distance
/// (simplify resolves a relative one). `qem lod` refits each level with them, as `simplify` would.
RefitOptions refit_options_for(const SimplifyOptions& options);

}  // namespace qem
