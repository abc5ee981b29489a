// AttributeWeights::normal_per_spacing and color_per_spacing: the normal and colour weights of a
// run, from the spacing of the faces it is asked for. Resolved once where a run starts (simplify,
// simplify_partitioned, each glTF primitive), so that every stage of the run (the wedges' quadrics,
// the far-place repair, the attribute fit) and every run of one glTF primitive (its watched run and
// its final one, which must contract in the same order) weighs the attributes alike.
#pragma once

#include "qem/mesh.h"
#include "qem/simplify.h"

namespace qem {

/// Whether `options` still has a weight to resolve for `input` (normals or colours it carries).
bool spacing_weights_unresolved(MeshView input, const SimplifyOptions& options);

/// The normal weight a run of `options` (resolved) on `input` uses: 0 without normals.
double normal_weight_used(MeshView input, const SimplifyOptions& options);
/// The colour weight a run of `options` (resolved) on `input` uses: 0 without colours.
double color_weight_used(MeshView input, const SimplifyOptions& options);

/// The faces a run of `options` on `input` is asked for, as the core resolves its target (the
/// larger of a face and a ratio target; a vertex target alone: twice it), or 0 (no face target).
double asked_faces(MeshView input, const SimplifyOptions& options);

/// `options` with the normal weight at least normal_per_spacing times the spacing of
/// `target_faces` faces on `input`'s surface (in diagonals of its referenced vertices' box), the
/// colour weight at least color_per_spacing times it but no more than AttributeWeights::
/// color_spacing_cap from it (each only where `input` has that kind), and both factors 0. Without
/// a target (0) the weights stay as they are.
SimplifyOptions with_spacing_weights(MeshView input, SimplifyOptions options, double target_faces);
inline SimplifyOptions with_spacing_weights(MeshView input, const SimplifyOptions& options) {
  return with_spacing_weights(input, options, asked_faces(input, options));
}

}  // namespace qem
