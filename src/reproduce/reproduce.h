// `qem reproduce`: re-runs the experiments behind the figures of GH97 (Figs. 5, 6, 7, 15-17) and
// HG99 (Fig. 8) on the shared models and writes, per figure, a Markdown table, a CSV and an SVG plot.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace qem::reproduce {

/// Figure ids, in output order.
inline const std::vector<std::string> kFigures = {"gh97_fig5", "gh97_fig6", "gh97_fig7", "gh97_fig15_17",
                                                  "hg99_fig8"};

struct Options {
  std::string data_dir;           ///< folder holding gh_cow.obj, gh_foot_bones.off, ...
  std::string out_dir;            ///< created if missing
  bool quick = false;             ///< fewer samples, models and repetitions (seconds instead of minutes)
  std::vector<std::string> only;  ///< subset of kFigures (empty = all)
  std::function<void(const std::string&)> log;  ///< progress lines, may be empty
};

struct FigureResult {
  std::string id, title;
  std::string markdown;                  ///< the table (and a short note), as written to <id>.md
  std::vector<std::string> files;        ///< paths written
  std::map<std::string, double> values;  ///< key numbers, for tests and the summary
};

/// Principal curvatures (k1 >= k2, positive on a convex surface) of the ellipsoid
/// x^2/a^2 + y^2/b^2 + z^2/c^2 = 1, axes = {a, b, c}, at p after projecting p radially onto it
/// (simplified vertices leave the surface). HG99 Fig. 8's "underlying ellipsoid".
void ellipsoid_curvatures(const double axes[3], const double p[3], double& k1, double& k2);

/// Runs the selected experiments. Throws qem::Error when the data folder or a model is missing or
/// a figure id is unknown. Results other than timings are deterministic.
std::vector<FigureResult> run(const Options& options);

}  // namespace qem::reproduce
