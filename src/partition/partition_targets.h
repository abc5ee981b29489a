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

/// A part's targets (0 where `total` has none): its share of `total` in proportion to its faces
/// (of `all_faces`) or vertices (of `all_vertices`), the faces' share 1.25x, plus two faces (one
/// vertex) per vertex on its cut (`locked`). See split_mesh.cpp for why.
Targets part_targets(const Targets& total, std::size_t part_faces, std::size_t all_faces,
                     std::size_t part_vertices, std::size_t all_vertices, std::size_t locked);

}  // namespace qem::partition_detail
