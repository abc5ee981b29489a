// `qem reproduce`: re-runs the experiments of GH97 Figs. 5, 6, 7, 15-17 and HG99 Fig. 8 on the shared
// models and writes a Markdown table, a CSV and an SVG plot per figure (see docs/reproduction.md).
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include "cli_util.h"
#include "command.h"
#include "qem/error.h"
#include "reproduce/reproduce.h"

namespace qem::cli {

namespace {

struct ReproduceArgs {
  reproduce::Options options;
  std::string only;
  bool quiet = false;
};

int run_reproduce(ReproduceArgs& args) {
  std::stringstream ss(args.only);
  for (std::string id; std::getline(ss, id, ',');)
    if (!id.empty()) args.options.only.push_back(id);
  if (!args.quiet) args.options.log = [](const std::string& s) { std::fprintf(stderr, "%s\n", s.c_str()); };
  Stopwatch clock;
  auto results = reproduce::run(args.options);
  for (const auto& r : results) {
    std::printf("%s\n", r.markdown.c_str());
    for (const auto& f : r.files) std::printf("  wrote %s\n", f.c_str());
    std::printf("\n");
  }
  std::printf("%zu figures in %.1f s; summary in %s/summary.md\n", results.size(), clock.seconds(),
              args.options.out_dir.c_str());
  return 0;
}

const bool registered = register_command(90, [](CLI::App& app) -> std::function<int()> {
  auto args = std::make_shared<ReproduceArgs>();
  args->options.data_dir = "../shared/data";
  CLI::App* cmd = app.add_subcommand(
      "reproduce",
      "Re-run the experiments of GH97 Figs. 5, 6, 7, 15-17 and HG99 Fig. 8 on the shared models; writes "
      "<figure>.md, .csv and .svg per figure and summary.md into OUTDIR");
  cmd->add_option("outdir", args->options.out_dir, "Output folder (created if missing)")->required();
  cmd->add_option("--data", args->options.data_dir,
                  "Folder with the models (gh_cow.obj, gh_foot_bones.off, gh_bunny_zipper.ply, "
                  "terrain_gcanyon_179k.ply, synth_cubes_10x10.ply, synth_ellipsoid_11k_curv.ply)")
      ->capture_default_str();
  cmd->add_flag(
      "--quick", args->options.quick,
      "Fewer samples (20k instead of 1M), models (no bunny/terrain timings), thresholds and repetitions");
  cmd->add_option("--only", args->only,
                  "Comma-separated subset of gh97_fig5, gh97_fig6, gh97_fig7, gh97_fig15_17, hg99_fig8");
  cmd->add_flag("--quiet", args->quiet, "No progress lines on stderr");
  return [args] { return run_reproduce(*args); };
});

}  // namespace

}  // namespace qem::cli
