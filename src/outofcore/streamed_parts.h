// Out of core by parts: an input a few times larger than the memory budget is cut on disk into
// parts that each fit (ranges of the Morton curve of the face centroids, as qem/partition.h cuts
// in memory), each part is read back and simplified with the vertices it shares with another part
// locked, and the welded parts take one in-core pass to the target. It is the partitioned run of
// qem/partition.h with its parts on disk: every input face is contracted by GH97, none is
// clustered, so the result is that run's quality (issue 20's bar, docs/out-of-core.md "By parts").
// It costs about an in-core run's time, where clustering (out_of_core.cpp) costs one pass over
// the input, so it is taken only where the budget would starve the clustering's phase 2 and the
// input is within a few budgets (plan_streamed_parts).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "outofcore/parallel_clustering.h"
#include "qem/simplify.h"

namespace qem::outofcore {

/// Peak memory of the in-core path per input face (load, working mesh, heap, refit), the figure
/// measured for issue 20; the decision in-core / out-of-core uses it.
inline constexpr double kInCoreBytesPerFace = 180;

struct StreamedPartsPlan {
  unsigned parts = 0;       ///< 0: not by parts (cluster instead)
  unsigned concurrent = 1;  ///< parts simplified at once, one a thread
  double share_slack = 0;   ///< a part's share of the target over its proportion (part_targets)
};

/// Parts for `faces` triangles on `vertices` vertices to `target_faces` under `budget` bytes, of
/// which `resident` are already taken (positions kept in memory), on `threads` threads: the fewest
/// (a power of two, at most 64) such that the parts being simplified at once, the per-vertex
/// arrays of the cut and the final pass fit, the parts given the larger of two shares of the
/// target with which they do (streamed_parts.cpp's kShareSlack, else the in-memory run's). {0}
/// when the input is more than kMaxBudgets budgets (clustering is then much faster, and its phase 2
/// gets tens of times the target anyway at the sizes where this would be slow) or no such count
/// exists.
StreamedPartsPlan plan_streamed_parts(std::uint64_t faces, std::uint64_t vertices, std::size_t target_faces,
                                      double budget, double resident, unsigned threads);

struct StreamedPartsReport {
  unsigned parts = 0;
  std::uint64_t shared_vertices = 0;  ///< input vertices on a cut, locked in the parts
  std::uint64_t merged_faces = 0;     ///< faces of the welded parts, the final pass's input
};

/// Simplifies the PLY at `path` (indexed: MeshStream::indexed()) by parts. `positions` are its
/// vertices' (out_of_core.cpp's PositionStore), `lo` and `extent` its bounding box's corner and
/// longest side. `options` must have their targets resolved (a face or vertex target, no ratio)
/// and are those of each part and of the final pass; their refit fits the output to the input
/// part by part, each part's input read back (no far-place repair). `progress(f)` is called on the calling
/// thread with the fraction done; it may throw to cancel. Temporary data goes to one file in `temp_dir`,
/// removed in every case. The same bytes on any thread count: the parts and their order do not depend on it.
/// False (and `result` untouched) when the parts dropped duplicate faces and options.two_sided would put a
/// sheet's reversed copies back: a whole run does that, so the caller clusters instead.
bool simplify_streamed_parts(const std::string& path, const PositionSource& positions, const double lo[3],
                             double extent, const SimplifyOptions& options, const StreamedPartsPlan& plan,
                             const std::string& temp_dir, const std::function<void(double)>& progress,
                             SimplifyResult& result, StreamedPartsReport* report = nullptr);

}  // namespace qem::outofcore
