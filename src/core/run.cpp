#include "core/run.h"

#include <algorithm>
#include <optional>

#include "core/border_placement.h"
#include "core/component_guard.h"
#include "core/context.h"
#include "core/fundamental_quadrics.h"
#include "core/order_greedy.h"
#include "core/order_passes.h"
#include "core/pair_set.h"
#include "core/parallel_chunks.h"
#include "core/settings.h"
#include "core/valid_pairs.h"
#include "core/wedges.h"
#include "core/working_mesh.h"
#include "qem/error.h"

namespace qem::core {

namespace {

// The mesh with what the contractions left of it, and the maps the caller asked for.
void finish(Context& c, std::optional<ContractionMap>& map, MeshView input, SimplifyResult& result,
            WedgeRefitData* refit) {
  if (c.wedges) {
    result.mesh = build_wedge_output(c.mesh, *c.wedges, input, result.vertex_source, result.face_source,
                                     map ? &result.output_vertex_of_input : nullptr, refit);
    return;
  }
  std::vector<std::uint32_t> output_index;
  result.mesh = build_output(c.mesh, input, &result.vertex_source, &result.face_source,
                             map ? &output_index : nullptr);
  if (map) {
    map->renumber(output_index, 0);
    result.output_vertex_of_input = map->take();
  }
}

// A working vertex is locked when any input vertex on it is.
void lock_vertices(std::span<const std::uint8_t> lock, MeshView input, const Wedges* wedges, WorkingMesh& mesh) {
  if (lock.size() != input.vertex_count())
    throw Error("vertex_lock has " + std::to_string(lock.size()) + " entries for " +
                std::to_string(input.vertex_count()) + " vertices");
  mesh.locked.assign(mesh.vertex_count(), 0);
  if (wedges) {
    for (std::uint32_t w = 0; w < wedges->count(); ++w)
      if (lock[wedges->source[w]]) mesh.locked[wedges->vertex[w]] = 1;
  } else {
    for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) mesh.locked[v] = lock[mesh.source_vertex[v]] != 0;
  }
}

// Whether some attribute takes more than one value. Forgetting with attributes is off by default
// because renewed attribute quadrics may shift error into the attributes; constant ones (the
// material carrier of a mesh whose only appearance is its faces' materials) have none to shift, and
// their seams are the material boundaries, whose planes forgetting renews as the border's.
bool any_varies(std::span<const VertexAttribute> attributes) {
  for (const VertexAttribute& a : attributes)
    for (std::size_t i = a.components; i < a.values.size(); ++i)
      if (a.values[i] != a.values[i % a.components]) return true;
  return false;
}

}  // namespace

SimplifyResult run(MeshView input, const SimplifyOptions& options, const RunHooks& hooks) {
  validate(options);
  SimplifyResult result;
  std::vector<std::uint32_t> internal;  // with attributes: each input vertex's working vertex
  WorkingMesh mesh = prepare_input(input, &internal);  // check, drop degenerate and duplicate faces, frame
  std::optional<Wedges> wedges;  // with attributes, on the input's vertices (Hoppe 1999)
  if (!input.attributes.empty()) wedges.emplace(build_wedges(input, internal, mesh, options));
  const bool varying_attributes = wedges && any_varies(input.attributes);  // before they are consumed
  const bool keep_input = hooks.reversed_twins && !mesh.reversed_twins.empty();
  if (hooks.reversed_twins) *hooks.reversed_twins = mesh.reversed_twins;
  if (wedges && hooks.consumed_attributes && !keep_input)
    for (VertexAttribute& a : *hooks.consumed_attributes) std::vector<double>().swap(a.values);
  std::vector<std::uint32_t>().swap(internal);
  if (!options.vertex_lock.empty()) lock_vertices(options.vertex_lock, input, wedges ? &*wedges : nullptr, mesh);
  if (wedges && options.lock_seams) lock_seam_vertices(*wedges, mesh);
  result.input_faces = mesh.faces_alive, result.input_vertices = mesh.vertices_alive;
  result.dropped_degenerate_faces = mesh.dropped_degenerate, result.dropped_duplicate_faces = mesh.dropped_duplicate;
  // targets from the input, before pruning
  const Settings settings = resolve(options, mesh, varying_attributes);
  // Without pruning, the component guard (made below, on the same faces) counts the input's
  // components; otherwise they are counted here, before the pruning.
  const bool guard_counts = settings.keep_components && settings.prune_size == 0;
  if (!guard_counts) result.input_components = count_components(mesh);
  if (settings.prune_size > 0)
    result.pruned_components = prune_components(mesh, wedges ? &*wedges : nullptr, settings.prune_size);
  std::optional<ContractionMap> map;
  if (options.map_input_vertices || hooks.map_input_vertices) map.emplace(input.vertex_count(), mesh.source_vertex);
  if (hooks.consumed_indices) {
    if (hooks.before_release) hooks.before_release(input);
    if (!keep_input) {
      input.indices = {};
      std::vector<std::uint32_t>().swap(*hooks.consumed_indices);
    }
  }
  if (hooks.observer) hooks.observer->on_start(mesh.face_source);

  std::vector<Quadric> quadric;
  PairSet pairs;
  Context c{settings, input, mesh, pairs, quadric, hooks.observer,
            hooks.observer && hooks.observer->wants_contractions(), map ? &*map : nullptr, {}, {}, result};
  if (wedges) c.wedges = &*wedges;
  SurfaceDistance surface;  // the input surface, for max_distance (distance_bound.h)
  if (std::isfinite(settings.max_distance)) {
    surface = SurfaceDistance(live_face_corners(mesh));
    c.surface = &surface;
  }
  if (c.done()) {
    if (guard_counts) result.input_components = count_components(mesh);
    result.stop_reason = StopReason::AlreadyBelowTarget;
    result.stop_detail = stop_detail(result.stop_reason, result, settings.lock_border);
    result.output_components = count_components(mesh);
    finish(c, map, input, result, hooks.wedge_refit);
    return result;
  }
  mesh.rebuild_face_lists();
  std::vector<Edge> edges;
  side_by_side(  // GH97 §5 (HG99 §2) and the edges of §3.2: independent, so side by side
      settings.threads, [&] { face_quadrics(mesh, settings.weighting, 1, quadric); },
      [&] { edges = unique_edges(mesh.tri, mesh.vertex_faces, mesh.vertex_count()); });
  add_constraint_planes(mesh, edges, settings, wedges.has_value(), quadric);  // GH97 §6, seams
  if (settings.exact_border) mark_border_corners(mesh, edges);  // after: the border is marked
  pairs = select_pairs(mesh, std::move(edges), settings.threshold);                         // GH97 §3.2
  result.virtual_pairs = pairs.virtual_count;
  c.marks.assign(mesh.vertex_count(), 0);
  std::optional<ComponentGuard> components;  // after add_constraint_planes: it tells closed from open
  if (settings.keep_components) c.components = &components.emplace(mesh);
  if (guard_counts) result.input_components = components->initial_count();

  result.stop_reason = StopReason::TargetReached;  // GH97 §4: contract until a stop criterion holds
  if (settings.scheme == Scheme::Passes) {
    run_passes(c, hooks.after_band);
  } else {
    run_greedy(c, nullptr, settings.first_forget_at(mesh.faces_alive));
    if (hooks.after_band) hooks.after_band(c, PassState{});
  }
  if (hooks.observer && result.stop_reason != StopReason::Cancelled) hooks.observer->on_progress(1.0);

  result.max_error_relative = c.max_error;
  result.max_error = c.max_error * mesh.frame.scale;
  result.stop_detail = stop_detail(result.stop_reason, result, settings.lock_border);
  result.output_components = count_components(mesh);
  finish(c, map, input, result, hooks.wedge_refit);
  return result;
}

}  // namespace qem::core
