// The partitioned run of qem/partition.h: the parts simplified side by side with their cuts locked,
// welded on the cut vertices, and one in-core pass over the merged mesh with the cuts unlocked
// (meshoptimizer's clusterlod recursion, one level: "merge neighbours, simplify again with the old
// borders unlocked").
#include <algorithm>
#include <atomic>
#include <chrono>
#include <ctime>
#include <functional>
#include <map>
#include <mutex>
#include <numeric>
#include <thread>

#include "analysis/disjoint_sets.h"
#include "core/parallel_chunks.h"
#include "core/release_memory.h"
#include "core/run.h"
#include "core/same_position.h"
#include "material_carrier.h"
#include "spacing_weights.h"
#include "partition/partition_targets.h"
#include "qem/error.h"
#include "qem/partition.h"
#include "refit/attribute_fit.h"
#include "refit/refit_after_simplify.h"
#include "refit/refit_points.h"
#include "refit_with_seams.h"

namespace qem {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Connected components of the input (faces joined through shared vertices), as simplify counts
// them on its input: union-find over the vertices (with attributes, the positions: `point`, see
// core/same_position.h; empty: the vertices) of the non-degenerate faces.
std::size_t count_input_components(MeshView input, const std::vector<std::uint32_t>& point) {
  analysis::DisjointSets parts(input.vertex_count());
  std::vector<std::uint8_t> used(input.vertex_count(), 0);
  const auto at = [&](std::uint32_t v) { return point.empty() ? v : point[v]; };
  for (std::size_t f = 0; f < input.face_count(); ++f) {
    const std::uint32_t t[3] = {at(input.indices[3 * f]), at(input.indices[3 * f + 1]), at(input.indices[3 * f + 2])};
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    for (int k = 0; k < 3; ++k) used[t[k]] = 1;
    parts.unite(t[0], t[1]), parts.unite(t[0], t[2]);
  }
  std::size_t count = 0;
  for (std::uint32_t v = 0; v < input.vertex_count(); ++v) count += used[v] && parts.find(v) == v;
  return count;
}

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

void run_parts_on_threads(std::span<const MeshPart> parts, const SimplifyOptions& options,
                          std::span<MeshPartResult> results,
                          const std::function<bool(unsigned, unsigned)>& progress, PartitionReport& report) {
  // One part per thread, each single-threaded: the parts are the parallelism.
  SimplifyOptions one = options;
  one.threads = 1;
  std::atomic<unsigned> done{0};
  std::atomic<bool> cancelled{false};
  std::mutex report_lock;
  std::map<std::thread::id, double> cpu_of_thread;
  core::for_chunks(parts.size(), 1, core::resolve_threads(options.threads), [&](std::size_t p, std::size_t, std::size_t) {
    if (cancelled) return;
    const double cpu0 = thread_cpu_seconds();
    results[p] = simplify_part(parts[p], one);
    const double cpu = thread_cpu_seconds() - cpu0;
    const unsigned d = ++done;
    std::lock_guard<std::mutex> lock(report_lock);
    cpu_of_thread[std::this_thread::get_id()] += cpu;
    report.parts_cpu_seconds += cpu;
    if (progress && !progress(d, unsigned(parts.size()))) cancelled = true;
  });
  for (const auto& [thread, cpu] : cpu_of_thread)
    report.busiest_thread_cpu_seconds = std::max(report.busiest_thread_cpu_seconds, cpu);
  if (cancelled) throw Error("cancelled");
}

}  // namespace

MeshPartResult simplify_part(const MeshPart& part, const SimplifyOptions& options) {
  SimplifyOptions o = options;
  o.target_faces = part.target_faces;
  o.target_ratio = 0;
  o.target_vertices = part.target_vertices;
  o.vertex_lock = part.locked;
  o.vertex_protect = part.protect;
  o.refit_rounds = 0;         // the refit fits the final result to the whole input,
  o.fit_attributes = false;  // and so does the attribute fit,
  o.far_repair = false;      // and the far places are repaired there
  o.two_sided = TwoSided::None;  // twins are put back by a whole run only (simplify_partitioned)
  o.map_input_vertices = true;
  SimplifyResult r = simplify(MeshView(part.mesh), o);
  MeshPartResult out;
  out.mesh = std::move(r.mesh);
  out.vertex_source = std::move(r.vertex_source);
  out.face_source = std::move(r.face_source);
  out.output_vertex_of_input = std::move(r.output_vertex_of_input);
  out.input_faces = r.input_faces;
  out.contractions = r.contractions;
  out.rejected_topology = r.rejected_topology, out.rejected_inversion = r.rejected_inversion;
  out.rejected_error = r.rejected_error, out.rejected_component = r.rejected_component;
  out.dropped_duplicate_faces = r.dropped_duplicate_faces;
  out.max_error = r.max_error;
  return out;
}

namespace {

// finish_partitioned; `release` frees the parts and their results (once they are welded).
SimplifyResult finish(MeshView input, const SimplifyOptions& options, std::span<const MeshPart> parts,
                      std::span<const MeshPartResult> results, PartitionReport* report,
                      const std::function<void()>& release) {
  if (needs_material_carrier(input)) {  // as split_mesh gave the parts (material_carrier.h)
    SimplifyResult r = with_material_carrier(
        input, [&](MeshView with) { return finish(with, options, parts, results, report, release); });
    drop_material_carrier(r.mesh.attributes);
    return r;
  }
  if (parts.size() != results.size()) throw Error("finish_partitioned: one result per part is needed");
  constexpr std::uint32_t kNone = SimplifyResult::kUnmapped;
  // Weld: a vertex of a part's output that started as a cut vertex never moved and was never
  // removed (it was locked), so the parts' copies are one vertex, found through its input index.
  // With attributes a cut vertex is a wedge: the wedges of a seam on the cut stay apart (their
  // indices differ) at their common position, as in the input, and the final pass sees the seam.
  // A wedge on the cut takes the values of the first part that has it (the parts may have refitted
  // a locked wedge's normal or colour each on its side); a second copy of one input vertex from the
  // same part (the two sides of a mirror line, kept apart by that part) stays its own vertex.
  Mesh merged;
  for (const VertexAttribute& a : input.attributes) merged.attributes.push_back({a.name, a.kind, a.components, {}});
  std::vector<std::uint32_t> merged_source;  // per merged vertex: its input vertex
  std::vector<std::uint32_t> merged_face_source;
  std::vector<std::uint32_t> welded(input.vertex_count(), kNone);  // cut vertex -> merged vertex
  std::vector<std::uint32_t> welded_by(input.vertex_count(), kNone);  // the part that made it
  std::vector<std::vector<std::uint32_t>> merged_of(parts.size());  // per part output vertex
  std::size_t nondegenerate = 0, part_dups = 0, contractions = 0;
  SimplifyResult result;
  double max_error = 0;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const MeshPart& part = parts[p];
    const MeshPartResult& r = results[p];
    if (r.vertex_source.size() != r.mesh.vertex_count() || r.face_source.size() != r.mesh.face_count() ||
        r.output_vertex_of_input.size() != part.input_vertex.size() ||
        r.mesh.attributes.size() != merged.attributes.size() ||
        (!input.face_materials.empty() && !input.attributes.empty() &&
         r.mesh.face_materials.size() != r.mesh.face_count()))
      throw Error("finish_partitioned: part " + std::to_string(p) + "'s result does not match the part");
    nondegenerate += part.mesh.face_count();
    part_dups += r.dropped_duplicate_faces;
    contractions += r.contractions;
    result.rejected_topology += r.rejected_topology, result.rejected_inversion += r.rejected_inversion;
    result.rejected_error += r.rejected_error, result.rejected_component += r.rejected_component;
    max_error = std::max(max_error, r.max_error);
    std::vector<std::uint32_t>& to_merged = merged_of[p];
    to_merged.resize(r.mesh.vertex_count());
    for (std::size_t u = 0; u < r.mesh.vertex_count(); ++u) {
      const std::uint32_t g = part.input_vertex.at(r.vertex_source[u]);
      const bool cut = part.locked[r.vertex_source[u]] != 0;
      if (cut && welded[g] != kNone && welded_by[g] != p) {
        to_merged[u] = welded[g];
        continue;
      }
      to_merged[u] = std::uint32_t(merged_source.size());
      if (cut && welded[g] == kNone) welded[g] = to_merged[u], welded_by[g] = std::uint32_t(p);
      merged_source.push_back(g);
      merged.positions.insert(merged.positions.end(), &r.mesh.positions[3 * u], &r.mesh.positions[3 * u] + 3);
      for (std::size_t a = 0; a < merged.attributes.size(); ++a) {
        const std::size_t width = merged.attributes[a].components;
        const double* row = &r.mesh.attributes[a].values.at(width * u);
        merged.attributes[a].values.insert(merged.attributes[a].values.end(), row, row + width);
      }
    }
    for (std::size_t f = 0; f < r.mesh.face_count(); ++f) {
      for (int k = 0; k < 3; ++k) merged.indices.push_back(to_merged[r.mesh.indices[3 * f + k]]);
      merged_face_source.push_back(part.input_face.at(r.face_source[f]));
    }
    merged.face_materials.insert(merged.face_materials.end(), r.mesh.face_materials.begin(), r.mesh.face_materials.end());
  }
  if (report) report->merged_faces = merged.face_count();

  // The final pass: the same rules and target over the merged mesh, the cuts no longer locked
  // (the caller's locks still are).
  // A ratio is of the faces the parts simplified (their duplicates dropped), as the core's is.
  const partition_detail::Targets total = partition_detail::resolve_targets(options, nondegenerate - part_dups);
  SimplifyOptions o = partition_detail::final_pass_options(options, total);
  o.map_input_vertices = true;
  std::vector<std::uint8_t> lock, protect;
  if (!options.vertex_lock.empty()) {
    lock.resize(merged_source.size());
    for (std::size_t v = 0; v < lock.size(); ++v) lock[v] = options.vertex_lock[merged_source[v]];
    o.vertex_lock = lock;
  }
  if (!options.vertex_protect.empty()) {
    protect.resize(merged_source.size());
    for (std::size_t v = 0; v < protect.size(); ++v) protect[v] = options.vertex_protect[merged_source[v]];
    o.vertex_protect = protect;
  }
  // The core itself (as simplify runs it), for what the refit with attributes needs of each output
  // vertex: whether it is on a seam (core/wedges.h).
  const bool refit = options.refit_rounds > 0;
  const bool fit_values =
      options.fit_attributes && refit_detail::has_fitted_attributes(input.attributes, options.attribute_weights);
  core::WedgeRefitData wedge_refit;
  core::RunHooks hooks;
  hooks.consumed_indices = &merged.indices;
  hooks.consumed_attributes = &merged.attributes;
  if ((refit || fit_values) && !merged.attributes.empty()) hooks.wedge_refit = &wedge_refit;
  const auto start = std::chrono::steady_clock::now();
  SimplifyResult last = core::run(MeshView(merged), o, hooks);
  std::vector<double>().swap(merged.positions);
  if (report) report->final_seconds = seconds_since(start);

  result.mesh = std::move(last.mesh);
  result.input_faces = nondegenerate - part_dups - last.dropped_duplicate_faces;
  result.dropped_degenerate_faces = input.face_count() - nondegenerate;
  result.dropped_duplicate_faces = part_dups + last.dropped_duplicate_faces;
  result.contractions = contractions + last.contractions;
  result.rejected_topology += last.rejected_topology, result.rejected_inversion += last.rejected_inversion;
  result.rejected_error += last.rejected_error, result.rejected_component += last.rejected_component;
  // With attributes the core counts positions, not wedges: its vertices and components are those
  // of the surface welded by position (core/working_mesh.cpp), and so are these.
  const std::vector<std::uint32_t> point = input.attributes.empty()
                                               ? std::vector<std::uint32_t>{}
                                               : core::first_at_same_position(input, core::resolve_threads(options.threads));
  result.input_components = count_input_components(input, point);
  result.output_components = last.output_components;
  result.stop_reason = last.stop_reason;
  result.stop_detail = last.stop_detail;
  result.max_error = std::max(max_error, last.max_error);
  const double diagonal = bounding_box(input).diagonal();
  result.max_error_relative = diagonal > 0 ? result.max_error / diagonal : 0;
  // Provenance in the input's numbering.
  result.vertex_source.resize(last.vertex_source.size());
  for (std::size_t v = 0; v < last.vertex_source.size(); ++v) result.vertex_source[v] = merged_source[last.vertex_source[v]];
  result.face_source.resize(last.face_source.size());
  for (std::size_t f = 0; f < last.face_source.size(); ++f) result.face_source[f] = merged_face_source[last.face_source[f]];
  // Where each input vertex went: into a part's output vertex, that one into the final output.
  std::vector<std::uint32_t> went(input.vertex_count(), kNone);
  std::vector<std::uint8_t> seen(input.vertex_count(), 0);
  for (std::size_t p = 0; p < parts.size(); ++p)
    for (std::size_t l = 0; l < parts[p].input_vertex.size(); ++l) {
      const std::uint32_t g = parts[p].input_vertex[l];
      if (seen[g]) continue;
      seen[g] = 1;
      const std::uint32_t u = results[p].output_vertex_of_input[l];
      if (u != kNone) went[g] = last.output_vertex_of_input[merged_of[p].at(u)];
    }
  if (!point.empty())
    for (std::uint32_t v = 0; v < input.vertex_count(); ++v)
      if (seen[v] && point[v] != v) seen[point[v]] = 1, seen[v] = 0;
  std::size_t referenced = 0;
  for (std::uint8_t s : seen) referenced += s;
  result.input_vertices = referenced;
  result.output_vertex_of_input = std::move(went);
  // Nothing below reads the parts or the welding's arrays.
  for (auto* v : {&merged_source, &merged_face_source, &welded, &welded_by}) std::vector<std::uint32_t>().swap(*v);
  std::vector<std::vector<std::uint32_t>>().swap(merged_of);
  std::vector<std::uint8_t>().swap(seen);
  if (release) release();
  core::release_free_memory_after(input.face_count());  // what the parts' runs freed, before the refit's arrays

  // The refit fits the result to the whole input, as simplify's own refit does, with the input's
  // surface: without it the refit has no Hausdorff guard and far points still pull, and it raised
  // the one-sided distance by a third on a bumpy sphere where simplify's refit keeps it.
  // With attributes, as simplify's: fitted welded by position with the seams held
  // (refit_with_seams), then the attribute fit, against the input's attributes.
  RefitOptions refit_options = refit_options_for(options, referenced, result.mesh.vertex_count());
  std::vector<std::uint8_t> fixed;  // per output vertex: the caller locked it
  if (!options.vertex_lock.empty()) {
    fixed.assign(result.mesh.vertex_count(), 0);
    for (std::size_t v = 0; v < fixed.size(); ++v) fixed[v] = options.vertex_lock[result.vertex_source[v]];
  }
  if (refit_options.rounds > 0 && result.contractions > 0) {
    const unsigned threads = core::resolve_threads(options.threads);
    const refit_detail::FitPoints points(input.positions, refit_detail::vertex_areas(input, threads), threads);
    const core::SurfaceDistance surface =
        refit_detail::surface_in_frame(input.positions, input.indices, points.frame(), threads);
    if (!fixed.empty()) refit_options.fixed_vertices = fixed;
    std::vector<std::uint32_t> closest_faces;  // the repair's start (simplify's)
    std::vector<std::uint32_t>* closest = options.far_repair ? &closest_faces : nullptr;
    const RefitResult fit =
        result.mesh.attributes.empty()
            ? refit_detail::refit_to_points(points, result.mesh, refit_options, result.output_vertex_of_input,
                                            &surface, closest)
            : refit_with_seams(points, result, refit_options, fixed, wedge_refit, &surface, closest);
    result.refit_rms_before = fit.rms_before;
    result.refit_rms_after = fit.rms_after;
    result.refit_rounds = fit.rounds;
    if (options.far_repair)  // after the refit, against the whole input, as simplify's
      repair_after_refit(result, options, input, points, surface,
                         seam_or_locked(wedge_refit.on_seam, fixed, result.mesh.vertex_count()),
                         closest_faces);
  }
  if (fit_values && result.contractions > 0) {
    // After the refit: the values fit the final positions. Seam and locked vertices keep theirs.
    const std::vector<std::uint8_t> held = seam_or_locked(wedge_refit.on_seam, fixed, result.mesh.vertex_count());
    refit_detail::fit_attributes(input.positions, input.indices, input.attributes, options.attribute_weights,
                                 result.output_vertex_of_input, held, result.mesh);
  }
  if (!options.map_input_vertices) std::vector<std::uint32_t>().swap(result.output_vertex_of_input);
  return result;
}

}  // namespace

SimplifyResult finish_partitioned(MeshView input, const SimplifyOptions& options, std::span<const MeshPart> parts,
                                  std::span<const MeshPartResult> results, PartitionReport* report) {
  return finish(input, options, parts, results, report, {});
}

SimplifyResult finish_partitioned(MeshView input, const SimplifyOptions& options, std::vector<MeshPart>&& parts,
                                  std::vector<MeshPartResult>&& results, PartitionReport* report) {
  std::vector<MeshPart> own_parts = std::move(parts);
  std::vector<MeshPartResult> own_results = std::move(results);
  return finish(input, options, own_parts, own_results, report, [&] {
    std::vector<MeshPart>().swap(own_parts);
    std::vector<MeshPartResult>().swap(own_results);
  });
}

SimplifyResult simplify_partitioned(MeshView input, const SimplifyOptions& options, const PartitionOptions& partition,
                                    PartitionReport* report) {
  check_options(options);
  // Once for the whole input: each part's run then weighs the normals and colours alike.
  if (spacing_weights_unresolved(input, options))
    return simplify_partitioned(input, with_spacing_weights(input, options), partition, report);
  PartitionReport local_report;
  PartitionReport& rep = report ? *report : local_report;
  const unsigned part_count = partition.parts > 0 ? partition.parts : automatic_parts(input.face_count());
  if (part_count <= 1) {
    rep.parts = 1;
    return simplify(input, options);
  }
  auto start = std::chrono::steady_clock::now();
  std::vector<MeshPart> parts = split_mesh(input, options, part_count, &rep);
  rep.split_seconds = seconds_since(start);
  start = std::chrono::steady_clock::now();
  std::vector<MeshPartResult> results(parts.size());
  if (partition.run_parts) {
    partition.run_parts(parts, options, results);
    if (partition.progress && !partition.progress(unsigned(parts.size()), unsigned(parts.size())))
      throw Error("cancelled");
  } else {
    run_parts_on_threads(parts, options, results, partition.progress, rep);
  }
  rep.parts_seconds = seconds_since(start);
  // Duplicate faces may be the reversed copies that make a sheet two-sided, which only a whole run
  // puts back (SimplifyOptions::two_sided: the rims' twins are found by the core that drops them,
  // and counted in the target by running again). Such an input is simplified whole instead.
  if (options.two_sided != TwoSided::None &&
      std::any_of(results.begin(), results.end(), [](const MeshPartResult& r) { return r.dropped_duplicate_faces > 0; })) {
    rep = PartitionReport{};
    rep.parts = 1;
    return simplify(input, options);
  }
  SimplifyResult out = finish_partitioned(input, options, std::move(parts), std::move(results), &rep);
  out.normal_weight = normal_weight_used(input, options);
  out.color_weight = color_weight_used(input, options);
  return out;
}

}  // namespace qem
