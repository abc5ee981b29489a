// Forgetting (SimplifyOptions::forget). GH97's quadrics remember every plane a vertex ever stood
// for (GH97 §4: Q = Q1 + Q2 at each contraction), so late contractions are ranked by their
// distance to faces long gone. Each time the faces have fallen by the factor, every quadric is
// made again from the current surface, as at the start, and every pair is costed afresh (the
// memoryless cost of Lindstrom & Turk 1998, renewed in steps; docs/benchmarks.md, "Forgetting").
#pragma once

#include "core/context.h"

namespace qem::core {

/// Every quadric made again from the current live faces (the face lists must be current): the
/// vertices' (GH97 §5, HG99 §2) with their border planes (GH97 §6) and, with attributes, the
/// wedges' (Hoppe 1999) from their current values, with the seam planes (seam_planes.h).
void renew_quadrics(Context& c);

}  // namespace qem::core
