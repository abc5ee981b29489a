// `qem replay RECORD OUTPUT --faces N`: rebuilds the mesh of any face count between a recorded
// run's output and its input (GH97 §3), byte-identical to `qem simplify INPUT OUTPUT --faces N`
// with the options the record was made with.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_util.h"
#include "command.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/progressive.h"

namespace qem::cli {
namespace {

struct ReplayArgs {
  std::string record, output;
  std::size_t faces = 0;
  double ratio = 0;
  bool ascii = false, quiet = false, force = false;
  bool double_values = false;  // --double
};

int run_replay(const ReplayArgs& a) {
  if (a.ratio < 0 || a.ratio > 1) throw Error("--ratio must be in (0, 1]");
  refuse_to_overwrite(a.record, a.output, a.force);
  Stopwatch total;
  const Record record = read_record(a.record);
  // No target: the whole run (M_g). --ratio as in `qem simplify`: of the faces the run started from.
  std::size_t target = 0;
  if (a.faces > 0) target = a.faces;
  if (a.ratio > 0)
    target = std::max(target, std::size_t(std::floor(a.ratio * double(record.base.face_count()))));
  const std::size_t targets[] = {target};
  const std::vector<ReplayLevel> level = replay_levels(record, targets);
  SaveOptions save;
  save.binary = !a.ascii;
  save.double_precision = a.double_values || record.double_input;
  save_mesh(a.output, level[0].mesh, save);
  if (!a.quiet) {
    if (target < record.final_faces())
      std::fprintf(stderr, "qem: note: the record ends at %zu faces, above the target %zu\n",
                   record.final_faces(), target);
    std::fprintf(stderr,
                 "qem: %zu -> %zu faces, %zu vertices, %zu of %zu contractions, max error %.4g, %.3f s\n",
                 record.base.face_count(), level[0].mesh.face_count(), level[0].mesh.vertex_count(),
                 level[0].contractions, record.size(), level[0].max_error, total.seconds());
  }
  return 0;
}

const bool registered = register_command(12, [](CLI::App& app) {
  auto args = std::make_shared<ReplayArgs>();
  CLI::App* sub = app.add_subcommand(
      "replay", "Rebuild the mesh at any face count from a contraction record (`qem simplify --record`)");
  sub->add_option("record", args->record, "Record file written by `qem simplify --record`")->required();
  sub->add_option("output", args->output, "Output mesh; format by extension (.obj .ply .stl .off)")
      ->required();
  sub->add_option("--faces,-f", args->faces,
                  "Stop at or below this many faces (as `qem simplify --faces`); default: replay everything");
  sub->add_option("--ratio,-r", args->ratio,
                  "Stop at or below this fraction of the recorded run's input faces");
  sub->add_flag("--ascii", args->ascii, "Write PLY / STL as text instead of binary");
  sub->add_flag("--double", args->double_values,
                "Write PLY values as double (default: as `qem simplify` did, double when its input PLY "
                "stored doubles)");
  sub->add_flag("--quiet,-q", args->quiet, "No summary on stderr");
  sub->add_flag("--force", args->force, "Allow the output to overwrite the record file");
  return [args] { return run_replay(*args); };
});

}  // namespace
}  // namespace qem::cli
