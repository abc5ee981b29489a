// `qem simplify INPUT OUTPUT [options]`: GH97 simplification of a mesh file.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "algorithm_options.h"
#include "cli_util.h"
#include "command.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/progressive.h"
#include "qem/simplify.h"

namespace qem::cli {
namespace {

struct SimplifyArgs {
  std::string input, output;
  std::size_t faces = 0, vertices = 0;
  double ratio = 0;
  double max_error = -1, max_error_rel = -1;
  double max_distance = -1, max_distance_rel = -1;
  AlgorithmArgs algorithm;
  bool ascii = false, json = false, quiet = false, force = false;
  bool double_values = false;  // --double
  std::string record;  // --record: the contraction sequence (docs/record-format.md)
};

// Shows the progress on a terminal and, with --record, keeps the contractions.
class Watcher : public ContractionRecorder {
 public:
  Watcher(bool show_progress, bool record) : show_progress_(show_progress), record_(record) {}
  bool wants_contractions() const override { return record_; }
  bool on_progress(double fraction) override {
    if (show_progress_) {
      std::fprintf(stderr, "\rqem: simplifying %5.1f%%", 100 * fraction);
      std::fflush(stderr);
    }
    return true;
  }

 private:
  bool show_progress_, record_;
};

int run_simplify(const SimplifyArgs& a) {
  refuse_to_overwrite(a.input, a.output, a.force);
  SimplifyOptions opt = to_simplify_options(a.algorithm);
  // A record replays the contractions, and a refit moves every vertex after them, so `qem replay`
  // could not give back what simplify wrote: with --record there is no refit (not the default's).
  if (!a.record.empty() && a.algorithm.refit_asked())
    throw Error(
        "--record cannot be combined with --refit: a record replays the contractions, and the refit "
        "moves every vertex after them, so `qem replay` could not give back what simplify wrote; "
        "use `qem lod --refit`, or `qem refit` on a replayed level");
  if (!a.record.empty()) opt.refit_rounds = 0;
  opt.target_faces = a.faces;
  opt.target_ratio = a.ratio;
  opt.target_vertices = a.vertices;
  if (a.max_error >= 0) opt.max_error = a.max_error;
  if (a.max_error_rel >= 0) opt.max_error = a.max_error_rel, opt.max_error_is_relative = true;
  if (a.max_distance >= 0) opt.max_distance = a.max_distance;
  if (a.max_distance_rel >= 0) opt.max_distance = a.max_distance_rel, opt.max_distance_is_relative = true;
  check_options(opt);  // before the input is read: a slip in the options is said at once

  const bool show_progress = !a.quiet && !a.json && ::isatty(STDERR_FILENO);

  Stopwatch total;
  LoadOptions load = to_load_options(a.algorithm);
  LoadReport report;
  Stopwatch t_load;
  Mesh mesh = load_input(a.input, load, &report);
  const double load_s = t_load.seconds();
  if (!a.record.empty() && !mesh.attributes.empty())
    throw Error(a.input + ": --record keeps positions and faces only, and this mesh has attributes (" +
                mesh.attributes.front().name + ", ...) that a replay would lose; simplify without --record, or " +
                "use `qem lod`, which makes each level with its attributes");

  Stopwatch t_simplify;
  const double cpu0 = process_cpu_seconds();
  Watcher watcher(show_progress, !a.record.empty());
  const std::size_t in_faces = mesh.face_count();
  // Without a record the input's faces are not needed afterwards: let the simplifier free them.
  SimplifyResult r = a.record.empty() ? simplify(std::move(mesh), opt, &watcher) : simplify(mesh, opt, &watcher);
  const double simplify_s = t_simplify.seconds();
  const double simplify_cpu_s = process_cpu_seconds() - cpu0;
  if (show_progress) std::fprintf(stderr, "\n");

  Stopwatch t_write;
  SaveOptions save;
  save.binary = !a.ascii;
  save.double_precision = a.double_values || report.double_precision;
  save_mesh(a.output, r.mesh, save);
  if (!a.record.empty()) {  // written atomically, like the mesh
    Record record = make_record(mesh, watcher.log);
    record.double_input = report.double_precision;  // so that replay writes what simplify wrote
    write_record(a.record, record);
  }
  const double write_s = t_write.seconds();

  if (a.json) {
    std::printf(
        "{\"tool\":\"qem\",\"in_faces\":%zu,\"target_faces\":%zu,\"out_faces\":%zu,\"out_vertices\":%zu,"
        "\"load_s\":%s,\"simplify_s\":%s,\"simplify_cpu_s\":%s,\"write_s\":%s,\"total_s\":%s,"
        "\"peak_rss_mb\":%s,\"max_error\":%s,\"max_error_rel\":%s,\"contractions\":%zu,\"virtual_pairs\":%zu,"
        "\"rejected_topology\":%zu,\"rejected_inversion\":%zu,\"rejected_error\":%zu,\"rejected_distance\":%zu,"
        "\"output_to_input_distance\":%s,\"refit_rounds\":%zu,"
        "\"refit_rms_before\":%s,\"refit_rms_after\":%s,\"dropped_degenerate\":%zu,\"dropped_duplicate\":%zu,"
        "\"stop\":\"%s\"}\n",
        in_faces, a.faces, r.mesh.face_count(), r.mesh.vertex_count(), json_number(load_s).c_str(),
        json_number(simplify_s).c_str(), json_number(simplify_cpu_s).c_str(), json_number(write_s).c_str(),
        json_number(total.seconds()).c_str(), json_number(peak_rss_mb()).c_str(),
        json_number(r.max_error).c_str(), json_number(r.max_error_relative).c_str(), r.contractions,
        r.virtual_pairs, r.rejected_topology, r.rejected_inversion, r.rejected_error, r.rejected_distance,
        json_number(r.output_to_input_distance).c_str(), r.refit_rounds,
        json_number(r.refit_rms_before).c_str(), json_number(r.refit_rms_after).c_str(),
        r.dropped_degenerate_faces, r.dropped_duplicate_faces, to_string(r.stop_reason));
  }
  if (!a.quiet)
    std::fprintf(stderr, "qem: %zu -> %zu faces, %zu vertices, max error %.4g (%.3g of diagonal), %.3f s; %s\n",
                 r.input_faces, r.mesh.face_count(), r.mesh.vertex_count(), r.max_error, r.max_error_relative,
                 total.seconds(), r.stop_detail.c_str());
  if (!a.quiet && r.dropped_degenerate_faces + r.dropped_duplicate_faces > 0)
    std::fprintf(stderr, "qem: left out %zu degenerate and %zu duplicate input faces\n", r.dropped_degenerate_faces,
                 r.dropped_duplicate_faces);
  if (!a.quiet && std::isfinite(opt.max_distance))
    std::fprintf(stderr, "qem: distance from the output to the input %.4g (sampled; bound %.4g%s), %zu contractions refused for it\n",
                 r.output_to_input_distance, opt.max_distance, opt.max_distance_is_relative ? " of the diagonal" : "",
                 r.rejected_distance);
  if (!a.quiet && opt.refit_rounds > 0)
    std::fprintf(stderr, "qem: refit in %zu round%s: RMS distance of the input's vertices %.4g -> %.4g\n",
                 r.refit_rounds, r.refit_rounds == 1 ? "" : "s", r.refit_rms_before, r.refit_rms_after);
  return 0;
}

const bool registered = register_command(10, [](CLI::App& app) {
  auto args = std::make_shared<SimplifyArgs>();
  CLI::App* sub = app.add_subcommand("simplify", "Simplify a mesh by quadric-error pair contraction (GH97)");
  sub->add_option("input", args->input, "Input mesh (.obj .ply .stl .off)")->required();
  sub->add_option("output", args->output, "Output mesh; format by extension (.obj .ply .stl .off)")->required();
  auto* g = sub->add_option_group("target", "Stop criteria (any combination; the first reached wins)");
  g->add_option("--faces,-f", args->faces, "Stop at or below this many faces");
  g->add_option("--ratio,-r", args->ratio, "Stop at or below this fraction of the input faces");
  g->add_option("--vertices", args->vertices, "Stop at or below this many vertices");
  g->add_option("--max-error", args->max_error,
                "Never make a contraction whose error exceeds this distance (model units): the error is "
                "sqrt(Q(v)/weight), the weighted RMS distance of the new vertex to the planes it represents");
  g->add_option("--max-error-rel", args->max_error_rel, "As --max-error, relative to the bounding-box diagonal");
  g->add_option("--max-distance", args->max_distance,
                "No output point farther than this from the input surface (model units): each contraction's "
                "new faces are certified against the input (sampled, with the sample spacing accounted for) "
                "and refused otherwise; the refit keeps it too. Alone: as few faces as the bound allows")
      ->check(CLI::PositiveNumber);
  g->add_option("--max-distance-rel", args->max_distance_rel, "As --max-distance, relative to the bounding-box diagonal")
      ->check(CLI::PositiveNumber);
  add_algorithm_options(sub, args->algorithm);
  sub->add_flag("--ascii", args->ascii, "Write PLY / STL as text instead of binary");
  sub->add_flag("--double", args->double_values, kDoubleOutputHelp);
  sub->add_flag("--json", args->json, "Print one JSON line with counts, timings, memory and error on stdout");
  sub->add_flag("--quiet,-q", args->quiet, "No progress and no summary on stderr");
  sub->add_flag("--force", args->force, "Allow the output to overwrite the input file");
  sub->add_option(
      "--record", args->record,
      "Also write the contraction sequence to this file, so `qem replay` / `qem lod` can rebuild "
      "any face count between the output's and the input's (docs/record-format.md); no default refit then");
  return [args] { return run_simplify(*args); };
});

}  // namespace
}  // namespace qem::cli
