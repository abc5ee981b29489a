// The face and vertex targets of a partitioned run, resolved once for the cut and again for the
// final pass, the same way both times.
#pragma once

#include <cstddef>

#include "qem/simplify.h"

namespace qem::partition_detail {

struct Targets {
  std::size_t faces = 0, vertices = 0;  ///< 0 = unused
};

/// `options`' face target (target_faces, or target_ratio of `faces`, the larger) and vertex target.
Targets resolve_targets(const SimplifyOptions& options, std::size_t faces);

/// The options of the final pass over the welded parts: `options` with the whole target `total`
/// and no refit, repair or attribute fit (the caller makes those against the input).
SimplifyOptions final_pass_options(const SimplifyOptions& options, const Targets& total);

/// The faces' share of a part in memory, over its proportion of the target: with the bare
/// proportion the 10M torus to 1 % in 16 parts had E 1.12x the in-core run's, with 1.25x 1.01x
/// (0.996-1.033x over the four meshes of docs/benchmarks.md's issue-20 table at 10 % and 1 %, for
/// no measurable time); with 1.6x sphere_1m3 to 10 % rose from 1.005x to 1.022x, and the larger
/// final pass is one thread's. (By parts on disk the refit is part by part and holds the cuts'
/// bands: there 1.6x does better, outofcore/streamed_parts.cpp.)
inline constexpr double kPartShareSlack = 1.25;

/// A part's targets (0 where `total` has none): its share of `total` in proportion to its faces
/// (of `all_faces`) or vertices (of `all_vertices`), the faces' share `share_slack` times that,
/// plus two faces (one vertex) per vertex on its cut (`locked`). See split_mesh.cpp for why.
Targets part_targets(const Targets& total, std::size_t part_faces, std::size_t all_faces,
                     std::size_t part_vertices, std::size_t all_vertices, std::size_t locked,
                     double share_slack);

}  // namespace qem::partition_detail
