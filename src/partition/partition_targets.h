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

}  // namespace qem::partition_detail
