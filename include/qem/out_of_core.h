// Simplifying a mesh file larger than memory: Garland & Shaffer 2002's two phases. Phase 1 is
// Lindstrom 2000's out-of-core vertex clustering: the input is read as a stream (binary PLY or
// binary STL, in chunks), every triangle's plane quadric is added to the grid cells of its corners
// (memory proportional to the occupied cells, not to the input), and the triangles that span three
// cells are written to a temporary file as cell triples; the triangles are clustered in blocks on
// every thread, added in file order. Phase 2 is the in-core simplification (qem::simplify, or
// part by part with qem/partition.h when large) of that clustered mesh down to the target. The
// grid is as fine as the memory budget allows, up to a multiple of the target (phase 2's time), so
// that phase 2, which decides quality, starts from a mesh tens of times larger than the target.
// Where the budget cannot give phase 2 that many and the input is within a few budgets, the input
// goes by parts on disk instead: the partitioned scheme of qem/partition.h, each part read back and
// simplified with its cut locked, the welded parts simplified to the target, then refitted and
// repaired part by part against the input (docs/out-of-core.md, "By parts").
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "qem/simplify.h"

namespace qem {

/// What a long out-of-core run is doing, for a progress display.
struct OutOfCoreProgress {
  const char* phase = "";  ///< "bounds", "clustering", "simplifying"
  int phase_index = 0;     ///< 1-based, of phase_count
  int phase_count = 0;
  std::uint64_t bytes_read = 0;   ///< of the input, all passes so far
  std::uint64_t bytes_total = 0;  ///< input bytes all passes will read
  double seconds = 0;             ///< since the run started
  double seconds_left = -1;       ///< estimated from the read rate; -1 when unknown
};

struct OutOfCoreOptions {
  /// Bytes the run may use; 0 = default_memory_limit().
  std::uint64_t memory_limit = 0;
  /// Folder of the temporary files; empty = $TMPDIR, else /tmp.
  std::string temp_dir;
  /// Phase 2 starts from at most about this many times the target's faces (the clustering's grid
  /// is sized for it, and coarsened when it gives more than twice as many): phase 2's time grows
  /// with its input, and beyond some tens of times the target its result hardly improves
  /// (docs/benchmarks.md, "Out of core"). 0: only the memory budget bounds it.
  double phase2_faces_per_target = 32;
  /// Parts of phase 2 (qem/partition.h): 0 = automatic_parts of the clustered faces (when the
  /// options allow a partitioned run), 1 = one in-core run.
  unsigned parts = 0;
  /// Called about once a second (and at each phase change); returning false cancels the run
  /// (qem::Error "cancelled"), after which no temporary file is left.
  std::function<bool(const OutOfCoreProgress&)> progress;
};

/// One phase of a run and how long it took.
struct OutOfCorePhase {
  std::string name;
  double seconds = 0;      ///< wall
  double cpu_seconds = 0;  ///< of the process, all threads (on a loaded machine wall says little)
};

struct OutOfCoreReport {
  std::uint64_t input_faces = 0, input_vertices = 0;
  std::uint64_t memory_limit = 0;        ///< the budget used (after the default)
  std::uint64_t grid_resolution = 0;     ///< cells along the bounding box's longest side
  unsigned grid_coarsenings = 0;         ///< times the sampled grid was too fine and was halved
  /// Times the grid was too coarse for the target and the faces were clustered again on a finer
  /// one (an input whose vertices lie along lines, as a CAD model's).
  unsigned grid_refinements = 0;
  /// Phase 2 stopped above the target where the clustering had folded thin parts together, and
  /// went on letting contractions make non-manifold edges (none opened a boundary edge).
  bool topology_relaxed = false;
  std::uint64_t clustered_vertices = 0;  ///< occupied cells
  std::uint64_t clustered_faces = 0;     ///< faces handed to phase 2 (after dropping duplicates)
  std::uint64_t temp_bytes_written = 0;
  std::uint64_t peak_memory_bytes = 0;  ///< peak resident set of the process (VmHWM)
  unsigned parts = 1;                   ///< parts of phase 2, or of the run by parts
  /// "clustering" (the two phases) or "parts" (by parts on disk: an input within a few budgets
  /// whose budget would starve phase 2; docs/out-of-core.md, "By parts").
  std::string method = "clustering";
  std::uint64_t shared_vertices = 0;  ///< by parts: input vertices on a cut, locked in the parts
  std::uint64_t merged_faces = 0;     ///< by parts: faces of the welded parts, the final pass's input
  /// Where the limit is below what the target needs (phase 2 never gets fewer cells than the
  /// target's faces): about the limit that would do, which the run takes instead of ending below
  /// the target. 0 when the limit is enough.
  std::uint64_t memory_needed = 0;
  std::size_t target_faces = 0;  ///< the face target, a ratio resolved against the input's faces
  std::vector<OutOfCorePhase> phases;
  /// What of the input the two phases do not carry (positions and faces only): a PLY's other
  /// vertex and face properties ("vertex red", "face red"...) and other elements, by name.
  std::vector<std::string> unread;
};

/// Half of the memory the kernel reports available (MemAvailable in /proc/meminfo), at least
/// 256 MB; 4 GB when it cannot be read.
std::uint64_t default_memory_limit();

/// Parses a size such as "2G", "512M", "1.5GB", "800000000" (bytes; K, M, G, T are powers of
/// 1024). Throws qem::Error on anything else.
std::uint64_t parse_memory_size(const std::string& text);

/// True when simplifying `path` in memory (load_mesh + simplify) is expected to stay within
/// `memory_limit` bytes (0 = default): about 180 bytes a face at peak, plus the file itself.
/// False also needs MeshStream to read the file (binary PLY or STL); other formats always say true.
bool fits_in_memory(const std::string& path, std::uint64_t memory_limit);

/// Simplifies the mesh file `path` in the two phases (or by parts, see the top of this file),
/// whatever its size, under the options' budget. `options` are those of qem::simplify and apply to phase 2 (its quadrics are recomputed
/// from the clustered faces); with refit_by_reduction, where phase 2 starts from fewer than 6
/// clustered faces an output face, the refit fits the output to the input's points instead
/// (one round, a fourth phase "refitting"; docs/out-of-core.md); target_ratio counts the input's faces; vertex_lock is refused; the
/// result does not depend on options.threads. Throws
/// qem::Error on a malformed input, an unwritable or full temporary folder, or a cancel; temporary files are
/// removed in every case (and on SIGINT/SIGTERM).
SimplifyResult simplify_out_of_core(const std::string& path, const SimplifyOptions& options,
                                    const OutOfCoreOptions& ooc = {}, OutOfCoreReport* report = nullptr);

}  // namespace qem
