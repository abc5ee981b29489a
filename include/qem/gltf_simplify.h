// Simplifying a whole glTF document (qem/gltf.h) in place: every simplifiable triangle primitive
// with its attributes, everything else passed through, and the target shared by the scene.
//
// Shared budget (the default, as gltfpack shares one error across a scene): a face / vertex target
// or an error limit is met by the primitives together, each stopping at about the same error in
// WORLD units (its contraction errors times GltfPrimitiveInfo::world_scale), so that a small, far
// or scaled-down part is not simplified more or less than the rest of what the viewer sees.
// How: a first run per primitive watches its contractions (SimplifyObserver) down to a floor and
// records its error curve, the running largest error against the faces left; one world threshold
// is chosen, the smallest at which the primitives' faces together meet the target; then each
// primitive is simplified again with the face count its curve gives at that threshold. The final
// runs are ordinary simplify() calls with a face target, so each output is what `qem simplify
// --faces N` gives on that primitive alone. The primitives of one mesh that meet (share a position:
// one surface split by material) are one such unit, simplified as one mesh whose material
// boundaries are seams and split back, so that the line where they meet is simplified without a
// crack (docs/attributes.md, "glTF"). Deterministic: threads only share out the units.
//
//   qem::GltfDocument doc = qem::GltfDocument::load("in.glb");
//   qem::SimplifyOptions opt;
//   opt.target_ratio = 0.25;
//   qem::GltfSimplifyReport r = qem::simplify_document(doc, opt);
//   doc.save("out.glb");
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "qem/gltf.h"
#include "qem/simplify.h"

namespace qem {

struct GltfSimplifyOptions {
  /// Apply the target to each primitive on its own (`qem simplify --per-mesh`): --ratio 0.5 halves
  /// every primitive, --faces N caps each at N. Off: the target is the scene's (see above).
  bool per_primitive = false;
  /// Primitives simplified at once (0 = all hardware threads). The output does not depend on it.
  unsigned threads = 0;
};

/// What happened to one primitive.
struct GltfPrimitiveOutcome {
  enum class Status {
    Simplified,  ///< replaced by its simplification
    Unchanged,   ///< simplifiable, but the target needed no contraction on it: left as it was
    Kept,        ///< not simplifiable (not TRIANGLES, no POSITION, no faces): passed through
  };
  std::size_t primitive = 0;  ///< index in GltfDocument::primitives()
  Status status = Status::Kept;
  std::size_t faces_in = 0, faces_out = 0;
  double world_scale = 1;  ///< GltfPrimitiveInfo::world_scale
  double max_error = 0;    ///< largest contraction error made, the primitive's own units
  double world_error = 0;  ///< the same times world_scale
  /// With a distance bound (SimplifyOptions::max_distance): the output's sampled distance to the
  /// primitive's input (SimplifyResult::output_to_input_distance) times world_scale; else 0.
  double world_distance = 0;
  /// Shared budget: the world error of the first contraction the primitive did not make (from its
  /// watched run), +inf when that run had none left. It exceeds the threshold unless the
  /// primitive stopped on the step that reaches it (world_error is then the threshold).
  double next_world_error = std::numeric_limits<double>::infinity();
  StopReason stop_reason = StopReason::AlreadyBelowTarget;
  std::string note;  ///< why it was kept, or "" (the document's notes() say it too)
};

/// "simplified", "unchanged" or "kept": the status as the command line's --json and Python report it.
const char* to_string(GltfPrimitiveOutcome::Status status);

struct GltfSimplifyReport {
  std::vector<GltfPrimitiveOutcome> primitives;  ///< one per document primitive, in order
  std::size_t simplified = 0, unchanged = 0, kept = 0;
  /// Triangles of the whole document before and after (kept primitives counted in both).
  std::size_t faces_in = 0, faces_out = 0;
  /// Shared budget: the faces the simplifiable primitives were to meet together (their input
  /// total when only an error limit was given, 0 as far as the checks allow), and the world-unit
  /// error threshold chosen.
  std::size_t target_faces = 0;
  double world_threshold = 0;
  double max_world_error = 0;  ///< the largest world_error of any primitive
  double max_world_distance = 0;  ///< the largest world_distance of any primitive
};

/// Simplifies every simplifiable primitive of `doc` (GltfDocument::replace) with `options`. The
/// stop criteria count the faces of the simplifiable primitives only (kept ones cannot change):
/// target_faces / target_ratio of their total, target_vertices as the same fraction of their
/// vertices; max_error and max_distance are in world units, max_error_is_relative and
/// max_distance_is_relative take them of the scene's bounding box diagonal
/// (GltfDocument::scene_mesh). With per_primitive, each primitive gets the options as they are,
/// max_error and max_distance still in world units (divided by its world_scale), relative ones of
/// the primitive's own diagonal. options.threads is
/// used inside each run when primitives are not run in parallel. Throws qem::Error on invalid
/// options (check_options) before anything is changed; the document is unchanged on error.
GltfSimplifyReport simplify_document(GltfDocument& doc, const SimplifyOptions& options,
                                     const GltfSimplifyOptions& gltf_options = {});

}  // namespace qem
