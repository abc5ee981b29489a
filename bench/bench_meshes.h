// Meshes built in code for the benchmarks, so qem_bench needs no data files and every run times
// exactly the same input.
#pragma once

#include <string>

#include "qem/mesh.h"

namespace qem::bench {

/// Icosphere with 20 * 4^level faces (level 6: 81,920; 7: 327,680; 8: 1,310,720), displaced
/// radially by 12 plane waves (wavelengths ~3 down to ~0.17, amplitude 0.12 / frequency) plus
/// +-0.001 per-vertex jitter: the recipe of the peer harness's `sphere_1m3.ply` (a closed, genus-0
/// "noisy scan"), with a C++ random generator, so the numbers differ but the character does not.
/// Built once per level and cached; deterministic.
const Mesh& bumpy_icosphere(int level);

/// A binary little-endian PLY (float xyz) of `bumpy_icosphere(level)` in the temporary directory,
/// written on first use and removed at exit.
const std::string& bumpy_icosphere_ply(int level);

}  // namespace qem::bench
