// `qem cluster`: uniform vertex clustering (Rossignac & Borrel 1993), the baseline GH97 §2 and
// Fig. 15 compare quadric simplification against; representatives placed by quadrics (Lindstrom 2000).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command.h"
#include "qem/cluster.h"
#include "qem/error.h"
#include "qem/io.h"

namespace qem::cli {

namespace {

struct ClusterArgs {
  std::string input, output, placement = "quadric";
  std::vector<int> grid;
  double cell = 0;
  bool cell_relative = false;
  bool force = false;
};

int run_cluster(const ClusterArgs& a) {
  const Stopwatch clock;
  refuse_to_overwrite(a.input, a.output, a.force);
  ClusterOptions o;
  if (!a.grid.empty()) {
    for (int k = 0; k < 3; ++k) o.grid[k] = a.grid[std::size_t(k)];
  } else if (a.cell > 0) {
    o.cell = a.cell;
    o.cell_relative = a.cell_relative;
  } else {
    throw Error("cluster: give --grid NX NY NZ or --cell SIZE");
  }
  o.placement = a.placement == "mean" ? ClusterPlacement::Mean : ClusterPlacement::Quadric;
  LoadReport report;
  const Mesh in = load_input(a.input, {}, &report);
  const Mesh out = cluster(in, o);
  SaveOptions save;
  save.double_precision = report.double_precision;  // a double PLY stays double, as in `qem simplify`
  save_mesh(a.output, out, save);
  std::printf("qem cluster: %s (%zu faces, %zu vertices) -> %s (%zu faces, %zu vertices) in %.3f s\n",
              a.input.c_str(), in.face_count(), in.vertex_count(), a.output.c_str(), out.face_count(),
              out.vertex_count(), clock.seconds());
  return 0;
}

const bool registered = register_command(40, [](CLI::App& app) -> std::function<int()> {
  auto args = std::make_shared<ClusterArgs>();
  CLI::App* cmd = app.add_subcommand(
      "cluster",
      "Simplify by uniform vertex clustering (Rossignac & Borrel 1993; the baseline of GH97): all vertices "
      "in a grid cell merge, faces with two corners in one cell vanish");
  cmd->add_option("input", args->input, "Input mesh (OBJ, PLY, STL, OFF)")->required();
  cmd->add_option("output", args->output, "Output mesh; format by extension")->required();
  auto* grid = cmd->add_option("--grid", args->grid, "Cells per axis over the bounding box: NX NY NZ")
                   ->expected(3)
                   ->check(CLI::PositiveNumber);
  auto* cell = cmd->add_option("--cell", args->cell, "Edge length of cubic cells (absolute units)")
                   ->check(CLI::PositiveNumber);
  cmd->add_flag("--cell-relative", args->cell_relative,
                "--cell is a fraction of the bounding-box diagonal (e.g. --cell 0.02 --cell-relative)")
      ->needs(cell);
  grid->excludes(cell);
  cmd->add_option("--placement", args->placement,
                  "Representative vertex: quadric (minimise the summed face quadrics, Lindstrom 2000) or "
                  "mean (average of the cell's vertices)")
      ->capture_default_str()
      ->check(CLI::IsMember({"quadric", "mean"}));
  cmd->add_flag("--force", args->force, "Allow the output to overwrite the input file");
  return [args] { return run_cluster(*args); };
});

}  // namespace

}  // namespace qem::cli
