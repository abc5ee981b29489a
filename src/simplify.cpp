// qem::simplify: the core's contraction pipeline (src/core/run.h, GH97 §4), then, when asked, the
// refit of the output to the input surface (src/refit, Hoppe et al. 1993), made once the core's
// arrays are freed, starting from the core's map of where each input vertex went.
#include "qem/simplify.h"

#include <algorithm>

#include "core/run.h"
#include "core/settings.h"
#include "qem/error.h"
#include "refit/refit_after_simplify.h"
#include "refit/refit_points.h"

namespace qem {

RefitOptions refit_options_for(const SimplifyOptions& options) {
  RefitOptions r;
  r.rounds = options.refit_rounds;
  r.points_per_vertex = options.refit_points_per_vertex;
  r.lock_border = options.lock_border;
  r.max_normal_turn_degrees = options.max_normal_turn_degrees;
  r.threads = options.threads;
  return r;
}

void check_options(const SimplifyOptions& options) {
  core::validate(options);
  if (options.refit_rounds > 0) refit_detail::check_options(refit_options_for(options));
}

namespace {

SimplifyResult simplify_and_refit(MeshView input, const SimplifyOptions& options, SimplifyObserver* observer,
                                  std::vector<std::uint32_t>* consumed_indices) {
  check_options(options);
  // The refit moves vertices to the input surface, which would pull seam vertices off their seams
  // and leave the attributes fitted to the old positions: not made with attributes.
  const bool refit = options.refit_rounds > 0 && input.attributes.empty();
  // The refit fits the input's vertices weighted by their share of the area: taken before the
  // core releases a consumed input's faces.
  std::vector<double> weights;
  core::RunHooks hooks;
  hooks.observer = observer;
  hooks.consumed_indices = consumed_indices;
  hooks.map_input_vertices = refit;
  if (refit) hooks.before_release = [&](MeshView in) { weights = refit_detail::vertex_areas(in); };
  SimplifyResult out = core::run(input, options, hooks);
  if (refit && out.contractions > 0 && out.stop_reason != StopReason::Cancelled) {
    if (!consumed_indices) weights = refit_detail::vertex_areas(input);
    const refit_detail::FitPoints points(input.positions, weights);
    RefitOptions refit_options = refit_options_for(options);
    std::vector<std::uint8_t> fixed;  // the locked vertices stay
    if (!options.vertex_lock.empty()) {
      fixed.assign(out.mesh.vertex_count(), 0);
      for (std::size_t v = 0; v < out.vertex_source.size(); ++v) fixed[v] = options.vertex_lock[out.vertex_source[v]];
      refit_options.fixed_vertices = fixed;
    }
    // Its first search for each input vertex's closest face starts at the vertex it went into.
    const RefitResult fit = refit_detail::refit_to_points(points, out.mesh, refit_options, out.output_vertex_of_input);
    out.refit_rms_before = fit.rms_before;
    out.refit_rms_after = fit.rms_after;
    out.refit_rounds = fit.rounds;
  }
  if (!options.map_input_vertices) std::vector<std::uint32_t>().swap(out.output_vertex_of_input);
  return out;
}

}  // namespace

SimplifyResult simplify(MeshView input, const SimplifyOptions& options, SimplifyObserver* observer) {
  return simplify_and_refit(input, options, observer, nullptr);
}

SimplifyResult simplify(Mesh&& input, const SimplifyOptions& options, SimplifyObserver* observer) {
  SimplifyResult out = simplify_and_refit(input, options, observer, &input.indices);
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
