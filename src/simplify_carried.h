// The library's internal path for Garland & Shaffer 2002's second phase: qem::simplify and the
// partitioned run (qem/partition.h) starting from quadrics a first phase accumulated (one per input
// vertex: the cluster's quadric of the original faces) instead of the input faces' own
// (core/fundamental_quadrics.h). The out-of-core run (src/outofcore) is its caller.
#pragma once

#include "core/fundamental_quadrics.h"
#include "qem/partition.h"
#include "qem/simplify.h"

namespace qem::detail {

/// qem::simplify with `carried` as the initial vertex quadrics (no vertex attributes).
SimplifyResult simplify_carrying(MeshView input, const SimplifyOptions& options, const core::CarriedQuadrics& carried,
                                 SimplifyObserver* observer = nullptr);
/// The same, releasing the input's faces once the core holds its own copy (as simplify(Mesh&&)).
SimplifyResult simplify_carrying(Mesh&& input, const SimplifyOptions& options, const core::CarriedQuadrics& carried,
                                 SimplifyObserver* observer = nullptr);

/// qem::simplify_partitioned with `carried` as the initial vertex quadrics: each part starts from
/// its vertices' quadrics, and the final pass over the welded parts from the sum of the quadrics of
/// the input vertices each merged vertex took in (what the parts' contractions accumulated, GH97
/// §4), so no pass recomputes them from the faces it sees. Parts run on std::threads.
SimplifyResult simplify_partitioned_carrying(MeshView input, const SimplifyOptions& options,
                                             const PartitionOptions& partition, const core::CarriedQuadrics& carried,
                                             PartitionReport* report = nullptr);

}  // namespace qem::detail
