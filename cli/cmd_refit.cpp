// `qem refit ORIGINAL APPROX OUTPUT`: moves an approximation's vertices to fit the original surface
// better, faces fixed (Hoppe et al. 1993 §4.2; src/refit). Works on any approximation: a level
// replayed from a record, or another tool's output.
#include <cstdio>
#include <memory>
#include <string>

#include "cli_util.h"
#include "command.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/refit.h"

namespace qem::cli {
namespace {

struct RefitArgs {
  std::string original, approx, output;
  RefitOptions options;
  bool ascii = false, json = false, quiet = false, force = false;
  bool double_values = false;  // --double
};

int run_refit(RefitArgs& a) {
  refuse_to_overwrite(a.approx, a.output, a.force);
  refuse_to_overwrite(a.original, a.output, a.force);
  const Stopwatch clock;
  const Mesh original = load_input(a.original);
  LoadReport report;
  Mesh approx = load_input(a.approx, {}, &report);
  const RefitResult r = refit(original, approx, a.options);
  SaveOptions save;
  save.binary = !a.ascii;
  save.double_precision = a.double_values || report.double_precision;
  save_mesh(a.output, approx, save);
  if (a.json)
    std::printf(
        "{\"tool\":\"qem refit\",\"faces\":%zu,\"vertices\":%zu,\"rounds\":%zu,\"vertices_held\":%zu,"
        "\"rms_before\":%s,\"rms_after\":%s,\"total_s\":%s}\n",
        approx.face_count(), approx.vertex_count(), r.rounds, r.vertices_held,
        json_number(r.rms_before).c_str(), json_number(r.rms_after).c_str(),
        json_number(clock.seconds()).c_str());
  if (!a.quiet)
    std::fprintf(stderr,
                 "qem: refit %zu faces in %zu round%s: RMS distance of the original's vertices %.4g -> %.4g "
                 "(%zu moves held back to keep faces from turning), %.3f s\n",
                 approx.face_count(), r.rounds, r.rounds == 1 ? "" : "s", r.rms_before, r.rms_after,
                 r.vertices_held, clock.seconds());
  return 0;
}

const bool registered = register_command(14, [](CLI::App& app) {
  auto args = std::make_shared<RefitArgs>();
  RefitOptions& o = args->options;
  CLI::App* sub = app.add_subcommand(
      "refit",
      "Move an approximation's vertices to fit the original surface better, faces unchanged: project the "
      "original's vertices onto it, solve for the positions by least squares, repeat (Hoppe et al. 1993)");
  sub->add_option("original", args->original, "The original mesh (.obj .ply .stl .off)")->required();
  sub->add_option("approx", args->approx, "The approximation to refit (e.g. a replayed level)")->required();
  sub->add_option("output", args->output, "Output mesh; format by extension")->required();
  sub->add_option("--rounds", o.rounds, "Project-and-solve rounds (each kept only if it lowers the error)")
      ->capture_default_str()
      ->check(CLI::Range(1u, 100u));
  sub->add_flag("--lock-border", o.lock_border, "Vertices on the approximation's border stay where they are");
  sub->add_option(
         "--max-turn", o.max_normal_turn_degrees,
         "A face whose normal would turn by more than this (degrees) keeps its vertices where they were")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 179.0));
  sub->add_option("--threads", o.threads, "Threads for the closest-point queries (0 = all; same result)")
      ->capture_default_str();
  sub->add_option(
         "--sample", o.points_per_vertex,
         "Fit to about this many of the original's vertices per approximation vertex, every k-th "
         "along a space-filling curve (0 = all). 4-8 keep most of the gain; the time saved grows with "
         "the original's vertices per approximation vertex")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
  sub->add_flag("--ascii", args->ascii, "Write PLY / STL as text instead of binary");
  sub->add_flag("--double", args->double_values, kDoubleOutputHelp);
  sub->add_flag("--json", args->json, "Print one JSON line with the fit's RMS before and after");
  sub->add_flag("--quiet,-q", args->quiet, "No summary on stderr");
  sub->add_flag("--force", args->force, "Allow the output to overwrite an input file");
  return [args] { return run_refit(*args); };
});

}  // namespace
}  // namespace qem::cli
