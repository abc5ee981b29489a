// qem::simplify: the core's contraction pipeline (src/core/run.h, GH97 §4), then, when asked, the
// refit of the output to the input surface (src/refit, Hoppe et al. 1993), made once the core's
// arrays are freed, starting from the core's map of where each input vertex went.
#include "qem/simplify.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "core/distance_bound.h"
#include "core/far_repair.h"
#include "core/parallel_chunks.h"
#include "core/release_memory.h"
#include "core/run.h"
#include "core/settings.h"
#include "geometry/box.h"
#include "geometry/frame.h"
#include "material_carrier.h"
#include "spacing_weights.h"
#include "qem/error.h"
#include "refit/attribute_fit.h"
#include "refit/refit_after_simplify.h"
#include "refit/refit_points.h"
#include "refit_with_seams.h"
#include "two_sided.h"

namespace qem {

RefitOptions refit_options_for(const SimplifyOptions& options) {
  RefitOptions r;
  r.rounds = options.refit_rounds;
  r.points_per_vertex = options.refit_points_per_vertex;
  // Exact borders: the refit does not move border vertices either (sliding one along a curved
  // border would take it off the input's polyline).
  r.lock_border = options.lock_border || options.exact_border;
  r.max_normal_turn_degrees = options.max_normal_turn_degrees;
  r.threads = options.threads;
  // max_distance in distance units (a relative one needs the input: simplify resolves it).
  if (!options.max_distance_is_relative) r.max_distance = options.max_distance;
  return r;
}

RefitOptions refit_options_for(const SimplifyOptions& options, std::size_t input_vertices,
                               std::size_t output_vertices) {
  RefitOptions r = refit_options_for(options);
  if (!options.refit_by_reduction || r.rounds == 0) return r;
  // Input vertices per output vertex: at about 2 (half the faces) any refit raised E, at about 4
  // one round on 2 points was the best, from about 6 two rounds on 8 (docs/benchmarks.md).
  const double per_vertex = output_vertices > 0 ? double(input_vertices) / double(output_vertices) : 0;
  if (per_vertex < 3) {
    r.rounds = 0;
  } else if (per_vertex < 6) {
    r.rounds = 1;
    r.points_per_vertex = 2;
  }
  return r;
}

namespace {

// Per point of `points`, whether it is on the input's border (`faces`), for relocations; empty
// when `mesh` has what a relocation could not give its new vertex (no relocation runs then).
std::vector<std::uint8_t> border_points_for(const Mesh& mesh, std::span<const std::uint32_t> faces,
                                            const refit_detail::FitPoints& points, unsigned threads) {
  if (!mesh.vertex_properties.empty()) return {};
  return core::points_on_border(faces, points.source, threads);
}

}  // namespace

// On a border a relocated vertex at an input vertex is on the input's border, as exact borders
// promise.
core::FarRepairResult repair_mesh(Mesh& mesh, const SimplifyOptions& options, MeshView input,
                                  std::span<const std::uint8_t> on_border,
                                  const refit_detail::FitPoints& points, const core::SurfaceDistance& surface,
                                  std::span<const std::uint8_t> held,
                                  std::span<const std::uint32_t> closest_faces) {
  const std::span<const double> positions = input.positions;
  core::FarRepairOptions repair_options;
  repair_options.held = held;
  repair_options.point_faces = closest_faces;
  repair_options.input_attributes = input.attributes;
  repair_options.point_source = points.source;
  repair_options.input_faces = input.indices;
  repair_options.attribute_weights = options.attribute_weights;
  repair_options.max_normal_turn_degrees = options.max_normal_turn_degrees;
  repair_options.threads = core::resolve_threads(options.threads);
  // Each relocation mends the one farthest place, until one cannot be made; a few were made on the
  // benchmark meshes (docs/benchmarks.md, "Far places"): the cap only bounds the work.
  repair_options.relocations = 256;
  repair_options.add_vertices = options.target_vertices == 0;  // a vertex target stays a bound
  repair_options.point_on_border = on_border;
  // None given: the repair finds them if a relocation at a border comes (as border_points_for).
  repair_options.find_border_points = on_border.empty() && mesh.vertex_properties.empty();
  core::FarRepairResult made =
      core::repair_far_places(mesh, points.frame(), surface, points.position, points.weight, repair_options);
  for (const core::Relocation& r : made.relocations)
    if (r.at_point)
      for (std::uint32_t v : {r.removed, r.added})
        if (v != UINT32_MAX)
          for (int k = 0; k < 3; ++k) mesh.positions[3 * std::size_t(v) + k] = positions[3 * std::size_t(points.source[r.point]) + k];
  return made;
}

void refit_levels(MeshView original, std::span<ReplayLevel> levels, const SimplifyOptions& options,
                  std::size_t input_vertices) {
  std::vector<std::pair<RefitOptions, std::vector<Mesh*>>> groups;
  for (ReplayLevel& level : levels) {
    const RefitOptions r = refit_options_for(options, input_vertices, level.mesh.vertex_count());
    if (r.rounds == 0) continue;
    auto same = std::find_if(groups.begin(), groups.end(), [&](const auto& g) {
      return g.first.rounds == r.rounds && g.first.points_per_vertex == r.points_per_vertex;
    });
    if (same == groups.end()) same = groups.insert(groups.end(), {r, {}});
    same->second.push_back(&level.mesh);
  }
  for (auto& [refit_options, meshes] : groups) qem::refit(original, meshes, refit_options);
  if (!options.far_repair || groups.empty() || std::isfinite(options.max_distance)) return;
  // Then the repair of the far places, as simplify makes it after its refit (the refitted levels only).
  const unsigned threads = core::resolve_threads(options.threads);
  const std::vector<double> weights = refit_detail::vertex_areas(original, threads);
  const refit_detail::FitPoints points(original.positions, weights, threads);
  const core::SurfaceDistance surface =
      refit_detail::surface_in_frame(original.positions, original.indices, points.frame(), threads);
  // A locked vertex never moves: a level's vertex at a locked input vertex's position is held.
  std::vector<std::array<double, 3>> locked;
  for (std::size_t v = 0; v < options.vertex_lock.size(); ++v)
    if (options.vertex_lock[v]) locked.push_back({original.positions[3 * v], original.positions[3 * v + 1], original.positions[3 * v + 2]});
  std::sort(locked.begin(), locked.end());
  // The input's border points, once for every level (the levels share the input and carry the
  // same kinds of data).
  const std::vector<std::uint8_t> on_border =
      border_points_for(*groups.front().second.front(), original.indices, points, threads);
  for (auto& [refit_options, meshes] : groups)
    for (Mesh* mesh : meshes) {
      std::vector<std::uint8_t> held(locked.empty() ? 0 : mesh->vertex_count(), 0);
      for (std::size_t v = 0; v < held.size(); ++v)
        held[v] = std::binary_search(locked.begin(), locked.end(),
                                     std::array<double, 3>{mesh->positions[3 * v], mesh->positions[3 * v + 1], mesh->positions[3 * v + 2]});
      repair_mesh(*mesh, options, original, on_border, points, surface, held, {});
    }
}

std::vector<std::uint8_t> seam_or_locked(std::span<const std::uint8_t> on_seam, std::span<const std::uint8_t> fixed,
                                         std::size_t vertices) {
  std::vector<std::uint8_t> held(vertices, 0);
  for (std::size_t v = 0; v < vertices; ++v)
    held[v] = (v < on_seam.size() && on_seam[v]) || (v < fixed.size() && fixed[v]);
  return held;
}

void repair_after_refit(SimplifyResult& result, const SimplifyOptions& options, MeshView input,
                        const refit_detail::FitPoints& points, const core::SurfaceDistance& surface,
                        std::span<const std::uint8_t> held, std::span<const std::uint32_t> closest_faces) {
  const core::FarRepairResult made =
      repair_mesh(result.mesh, options, input, {}, points, surface, held, closest_faces);
  result.edge_flips = made.flips;
  result.vertex_moves = made.moves;
  result.vertex_relocations = made.relocations.size();
  // Provenance across relocations: the removed vertex's inputs went into the kept one; the new
  // vertex starts from the input point it stands at (or nearest to); a face of a split is of the
  // face it divided.
  // (A new vertex is never removed again, so the inputs of removed vertices follow the relocations
  // in order, and the new vertices' sources are set after them.)
  std::vector<std::uint8_t> removed(result.mesh.vertex_count(), 0);
  for (const core::Relocation& r : made.relocations) removed[r.removed] = 1;
  for (std::uint32_t& v : result.output_vertex_of_input)
    if (v < removed.size() && removed[v])
      for (const core::Relocation& r : made.relocations)
        if (v == r.removed) v = r.kept;
  for (const core::Relocation& r : made.relocations) {
    if (r.point != UINT32_MAX) {
      const std::uint32_t source = points.source[r.point];
      if (r.removed < result.vertex_source.size()) result.vertex_source[r.removed] = source;
      if (r.added != UINT32_MAX && !result.vertex_source.empty()) result.vertex_source.push_back(source);
      if (source < result.output_vertex_of_input.size()) result.output_vertex_of_input[source] = r.removed;
    }
    for (int k = 0; k < 2; ++k)
      if (r.reused[k] < result.face_source.size()) result.face_source[r.reused[k]] = result.face_source[r.parent[k]];
  }
  // The face slots left empty go, as from the mesh's faces.
  std::vector<std::uint8_t> dropped(result.face_source.size(), 0);
  for (const core::Relocation& r : made.relocations)
    if (r.dropped < dropped.size()) dropped[r.dropped] = 1;
  std::size_t next = 0;
  for (std::size_t f = 0; f < result.face_source.size(); ++f)
    if (!dropped[f]) result.face_source[next++] = result.face_source[f];
  result.face_source.resize(next);
}

void check_options(const SimplifyOptions& options) {
  core::validate(options);
  if (options.refit_rounds > 0) refit_detail::check_options(refit_options_for(options));
}

namespace {

// The frame of the box of the vertices the faces use (the core's frame: relative options are
// fractions of its scale, the diagonal).
Frame referenced_frame(std::span<const double> positions, std::span<const std::uint32_t> indices) {
  BoxOfPoints box;
  for (std::uint32_t v : indices) box.add(&positions[3 * std::size_t(v)]);
  return frame_of_box(box.box());
}

// The largest distance from `approx` to the input surface over 15 samples of each face
// (core/distance_bound.h), in distance units: what the bound reached. `frame`: referenced_frame.
double sampled_distance(std::span<const double> positions, std::span<const std::uint32_t> indices, const Frame& frame,
                        const Mesh& approx) {
  const core::SurfaceDistance surface = refit_detail::surface_in_frame(positions, indices, frame);
  const auto at = [&](std::uint32_t v) {
    const double* p = &approx.positions[3 * std::size_t(v)];
    return frame.to_frame({p[0], p[1], p[2]});
  };
  double most = 0;
  for (std::size_t f = 0; f < approx.indices.size(); f += 3) {
    const std::uint32_t* t = &approx.indices[f];
    most = std::max(most, surface.triangle_sampled_max(at(t[0]), at(t[1]), at(t[2])));
  }
  return most * frame.scale;
}

SimplifyResult simplify_and_refit(MeshView input, const SimplifyOptions& options, SimplifyObserver* observer,
                                  std::vector<std::uint32_t>* consumed_indices,
                                  std::vector<VertexAttribute>* consumed_attributes,
                                  std::vector<TwinFaces>* reversed_twins) {
  check_options(options);
  const bool refit = options.refit_rounds > 0;
  const bool bounded = std::isfinite(options.max_distance);
  // The attribute fit (refit/attribute_fit.h) and the far-place repair (whose flips and moves must
  // not raise the error of appearance) read the input's attributes after the run: they are not
  // released to it then.
  const bool fit_values =
      options.fit_attributes && refit_detail::has_fitted_attributes(input.attributes, options.attribute_weights);
  if (fit_values || options.far_repair) consumed_attributes = nullptr;
  // The refit fits the input's vertices weighted by their share of the area, and its guard (and
  // the distance bound's report) measures against the input's faces: taken before the core
  // releases a consumed input's faces.
  std::vector<double> weights;
  std::vector<std::uint32_t> kept_indices;
  core::RunHooks hooks;
  hooks.observer = observer;
  hooks.consumed_indices = consumed_indices;
  hooks.consumed_attributes = consumed_attributes;
  hooks.map_input_vertices = refit || fit_values;
  hooks.reversed_twins = reversed_twins;
  core::WedgeRefitData wedge_refit;  // with attributes, for the refit, the attribute fit and the repair
  const bool repair = options.far_repair;
  if ((refit || fit_values || repair) && !input.attributes.empty()) hooks.wedge_refit = &wedge_refit;
  if (refit || bounded || fit_values || repair)
    hooks.before_release = [&](MeshView in) {
      if (refit || repair) weights = refit_detail::vertex_areas(in, core::resolve_threads(options.threads));
      kept_indices.assign(in.indices.begin(), in.indices.end());
    };
  SimplifyResult out = core::run(input, options, hooks);
  out.normal_weight = normal_weight_used(input, options);
  out.color_weight = color_weight_used(input, options);
  const std::span<const std::uint32_t> input_faces =
      consumed_indices ? std::span<const std::uint32_t>(kept_indices) : input.indices;
  // The frame of the refit and of the distance report: the input's referenced vertices' box.
  const Frame input_frame = bounded ? referenced_frame(input.positions, input_faces) : Frame{};
  double max_distance = options.max_distance;
  if (bounded && options.max_distance_is_relative) max_distance *= input_frame.scale;
  const RefitOptions chosen = refit_options_for(options, out.input_vertices, out.mesh.vertex_count());
  const bool finished = out.contractions > 0 && out.stop_reason != StopReason::Cancelled;
  const bool refitted = refit && chosen.rounds > 0 && finished;
  // The repair finishes the refit's work: not where the refit was asked for and the reduction left it
  // out (refit_by_reduction), so that such a run stays GH97's; alone (no refit asked), they run.
  // Nor under a distance bound, which the repair's samples do not certify.
  const bool repaired = repair && finished && (refitted || !refit) && !bounded;
  // The refit and the repair measure against the input's vertices (as points weighted by their
  // share of the area) and faces, in the points' frame.
  refit_detail::FitPoints points;
  core::SurfaceDistance surface;
  MeshView input_surface = input;  // the faces kept when the core consumed them
  input_surface.indices = input_faces;
  if (refitted || repaired) {
    core::release_free_memory_after(out.input_faces);  // what the core freed, before the refit's arrays
    const unsigned threads = core::resolve_threads(options.threads);
    if (!consumed_indices) weights = refit_detail::vertex_areas(input, threads);
    points = refit_detail::FitPoints(input.positions, weights, threads);
    std::vector<double>().swap(weights);  // the points keep theirs
    surface = refit_detail::surface_in_frame(input.positions, input_faces, points.frame(), threads);
  }
  std::vector<std::uint8_t> fixed;  // the locked vertices stay
  if (!options.vertex_lock.empty()) {
    fixed.assign(out.mesh.vertex_count(), 0);
    for (std::size_t v = 0; v < out.vertex_source.size(); ++v) fixed[v] = options.vertex_lock[out.vertex_source[v]];
  }
  // Each input point's closest face of the refitted output, found by the refit's local searches:
  // the repair's start, so that it does not search a tree of the output for every point.
  std::vector<std::uint32_t> closest_faces;
  if (refitted) {
    RefitOptions refit_options = chosen;
    refit_options.max_distance = max_distance;
    refit_options.fixed_vertices = fixed;
    // Its first search for each input vertex's closest face starts at the vertex it went into.
    const RefitResult fit =
        out.mesh.attributes.empty()
            ? refit_detail::refit_to_points(points, out.mesh, refit_options, out.output_vertex_of_input,
                                            &surface, repaired ? &closest_faces : nullptr)
            : refit_with_seams(points, out, refit_options, fixed, wedge_refit, &surface,
                               repaired ? &closest_faces : nullptr);
    out.refit_rms_before = fit.rms_before;
    out.refit_rms_after = fit.rms_after;
    out.refit_rounds = fit.rounds;
  }
  if (repaired)
    repair_after_refit(out, options, input_surface, points, surface,
                       seam_or_locked(wedge_refit.on_seam, fixed, out.mesh.vertex_count()), closest_faces);
  if (fit_values && out.contractions > 0 && out.stop_reason != StopReason::Cancelled) {
    // After the refit: the values fit the final positions. Seam and locked vertices keep theirs.
    const std::vector<std::uint8_t> held = seam_or_locked(wedge_refit.on_seam, fixed, out.mesh.vertex_count());
    refit_detail::fit_attributes(input.positions, input_faces, input.attributes,
                                 options.attribute_weights, out.output_vertex_of_input, held, out.mesh);
  }
  if (!options.map_input_vertices) std::vector<std::uint32_t>().swap(out.output_vertex_of_input);
  if (bounded) {
    out.output_to_input_distance = sampled_distance(input.positions, input_faces, input_frame, out.mesh);
    out.output_to_input_distance_relative = input_frame.scale > 0 ? out.output_to_input_distance / input_frame.scale : 0;
  }
  return out;
}

// The run, with the reversed twins of two-sided sheets put back (SimplifyOptions::two_sided,
// two_sided.h). The twins count in the targets: where they would pass one, the run is made again
// to a lower target (the core then keeps the input: it does not consume a mesh that has twins), at
// most three times; a run that stopped for another reason than its target is not made again (a
// lower target would not change it). The rims' twins are about as many at any nearby target (the
// rim's length), so the target falls by their number; all twins are a share of the output, so it
// falls to that share.
SimplifyResult simplify_two_sided(MeshView input, const SimplifyOptions& options, SimplifyObserver* observer,
                                  std::vector<std::uint32_t>* consumed_indices,
                                  std::vector<VertexAttribute>* consumed_attributes) {
  const bool wanted = options.two_sided != TwoSided::None && !(observer && observer->wants_contractions());
  const bool all = options.two_sided == TwoSided::All;
  std::vector<TwinFaces> twins;  // front input face, its reversed twin
  SimplifyOptions o = options;
  // The target for the fronts, when `have` of them would be joined by `added` twins.
  const auto lowered = [all](std::size_t target, std::size_t have, std::size_t added) -> std::size_t {
    if (all) return std::size_t(std::floor(double(target) * double(have) / double(have + added)));
    return target > added ? target - added : 0;
  };
  for (int run = 0;; ++run) {
    SimplifyResult out =
        simplify_and_refit(input, o, observer, consumed_indices, consumed_attributes, wanted ? &twins : nullptr);
    if (twins.empty() || out.stop_reason == StopReason::Cancelled) return out;
    const std::vector<std::uint32_t> faces =
        all ? faces_with_twins(out.face_source, twins)
            : faces_on_twinned_rims(out.mesh, out.face_source, twins, core::resolve_threads(options.threads));
    if (faces.empty()) return out;
    // A ratio is of the faces simplified, and with both sides kept, of their twins too (the output
    // of a sheet that is two-sided throughout is then that ratio of its input, both sides).
    const std::size_t ratio_of = out.input_faces + (all ? twins.size() : 0);
    std::size_t face_target = options.target_faces;
    if (options.target_ratio > 0)
      face_target = std::max(face_target, std::size_t(std::floor(options.target_ratio * double(ratio_of))));
    const std::size_t added_vertices = twin_vertices_needed(out.mesh, faces);
    const bool over_faces = face_target > 0 && out.mesh.face_count() + faces.size() > face_target;
    const bool over_vertices =
        options.target_vertices > 0 && out.mesh.vertex_count() + added_vertices > options.target_vertices;
    if ((over_faces || over_vertices) && run < 3 &&
        (out.stop_reason == StopReason::TargetReached || out.stop_reason == StopReason::AlreadyBelowTarget)) {
      if (over_faces) {
        o.target_ratio = 0;
        o.target_faces = lowered(face_target, out.mesh.face_count(), faces.size());
        if (o.target_faces == 0) o.as_far_as_possible = true;
      }
      if (over_vertices) {
        o.target_vertices = lowered(options.target_vertices, out.mesh.vertex_count(), added_vertices);
        if (o.target_vertices == 0) o.as_far_as_possible = true;
      }
      continue;
    }
    add_reversed_twins(out, faces, twins);
    return out;
  }
}

}  // namespace

SimplifyResult simplify(MeshView input, const SimplifyOptions& options, SimplifyObserver* observer) {
  if (spacing_weights_unresolved(input, options))
    return simplify(input, with_spacing_weights(input, options), observer);
  if (needs_material_carrier(input)) {
    SimplifyResult out = with_material_carrier(
        input, [&](MeshView with) { return simplify_two_sided(with, options, observer, nullptr, nullptr); });
    drop_material_carrier(out.mesh.attributes);
    return out;
  }
  return simplify_two_sided(input, options, observer, nullptr, nullptr);
}

SimplifyResult simplify(Mesh&& input, const SimplifyOptions& options, SimplifyObserver* observer) {
  if (spacing_weights_unresolved(input, options))
    return simplify(std::move(input), with_spacing_weights(input, options), observer);
  const bool carried = needs_material_carrier(input);
  if (carried) input.attributes.push_back(material_carrier(input.vertex_count()));
  SimplifyResult out = simplify_two_sided(input, options, observer, &input.indices, &input.attributes);
  if (carried) drop_material_carrier(out.mesh.attributes);
  out.mesh.material_names = std::move(input.material_names);
  out.mesh.material_library = std::move(input.material_library);
  return out;
}

void ContractionRecorder::on_start(std::span<const std::uint32_t> input_faces) {
  log = ContractionLog{};
  log.initial_faces.assign(input_faces.begin(), input_faces.end());
  std::sort(log.initial_faces.begin(), log.initial_faces.end());
}

void ContractionRecorder::on_contraction(const Contraction& c) {
  log.kept.push_back(c.kept);
  log.removed.push_back(c.removed);
  log.position.insert(log.position.end(), {c.position[0], c.position[1], c.position[2]});
  log.error.push_back(c.error);
  log.dead_faces.insert(log.dead_faces.end(), c.dead_faces.begin(), c.dead_faces.end());
  log.dead_begin.push_back(std::uint32_t(log.dead_faces.size()));
}

}  // namespace qem
