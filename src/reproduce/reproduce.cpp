// The experiments of GH97 §7 and HG99 §5, one function per figure.
#include "reproduce/reproduce.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "analysis/analyze_stats.h"
#include "io/io_common.h"
#include "qem/analyze.h"
#include "qem/cluster.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/measure.h"
#include "qem/mesh_info.h"
#include "qem/simplify.h"
#include "reproduce/svg_plot.h"

namespace qem::reproduce {

namespace {

namespace fs = std::filesystem;

/// A table written both as CSV (machine-readable) and as Markdown (for docs/reproduction.md).
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  std::string csv() const {
    std::string out;
    auto line = [&](const std::vector<std::string>& cells) {
      for (std::size_t i = 0; i < cells.size(); ++i) out += (i ? "," : "") + cells[i];
      out += '\n';
    };
    line(header);
    for (const auto& r : rows) line(r);
    return out;
  }
  std::string markdown() const {
    std::string out = "|";
    for (const auto& h : header) out += " " + h + " |";
    out += "\n|";
    for (std::size_t i = 0; i < header.size(); ++i) out += "---|";
    out += '\n';
    for (const auto& r : rows) {
      out += "|";
      for (const auto& c : r) out += " " + c + " |";
      out += '\n';
    }
    return out;
  }
};

std::string num(double v, const char* format = "%.4g") {
  if (!std::isfinite(v)) return v > 0 ? "inf" : "nan";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

class Context {
 public:
  explicit Context(const Options& o) : opt_(o) {
    if (o.data_dir.empty() || !fs::is_directory(o.data_dir))
      throw Error("reproduce: data folder '" + o.data_dir +
                  "' does not exist; pass --data DIR (the folder with gh_cow.obj, gh_foot_bones.off, ...)");
    fs::create_directories(o.out_dir);
  }

  const Options& options() const { return opt_; }
  bool quick() const { return opt_.quick; }
  std::size_t samples() const { return opt_.quick ? 20000 : 1000000; }

  const Mesh& model(const std::string& name) {
    auto it = cache_.find(name);
    if (it != cache_.end()) return it->second;
    fs::path path = fs::path(opt_.data_dir) / name;
    if (!fs::exists(path))
      throw Error("reproduce: model '" + path.string() + "' is missing from the data folder");
    log("loading " + name);
    return cache_.emplace(name, load_mesh(path.string())).first->second;
  }

  void log(const std::string& s) const {
    if (opt_.log) opt_.log(s);
  }

  double E(const Mesh& original, const Mesh& approx) const {
    MeasureOptions mo;
    mo.samples = samples();
    mo.seed = 1;
    return measure(original, approx, mo).E;
  }

  /// Writes <id>.csv, <id>.md and <id>.svg and fills the result's file list and markdown.
  void write(FigureResult& r, const Table& table, const Plot& plot, const std::string& note) const {
    fs::path base = fs::path(opt_.out_dir) / r.id;
    r.markdown = "### " + r.title + "\n\n" + table.markdown() + "\n" + note + "\n";
    io::write_file_atomic(base.string() + ".csv", table.csv());
    io::write_file_atomic(base.string() + ".md", r.markdown);
    io::write_file_atomic(base.string() + ".svg", render_svg(plot));
    r.files = {base.string() + ".csv", base.string() + ".md", base.string() + ".svg"};
  }

 private:
  Options opt_;
  std::map<std::string, Mesh> cache_;
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The simplifier as GH97 ran it: no link-condition test (GH97 has none: pair contraction must be
/// free to join parts and create non-manifold edges), inversions forbidden (GH97 §6), and the
/// library's area-weighted quadrics (HG99 §2; GH97 summed unweighted planes).
SimplifyOptions gh97_options(std::size_t target_faces, double threshold = 0) {
  SimplifyOptions o;
  o.target_faces = target_faces;
  o.threshold = threshold;
  o.preserve_topology = false;
  o.keep_components = false;  // as published: a part may contract to nothing (Fig. 16's vanished bones)
  return o;
}

// --- GH97 Fig. 5: running times to a 10-face approximation ------------------------------------------
// "Init" cannot be timed from outside the library, so it is measured as a run that stops after one
// contraction (target = input faces - 1): selecting valid pairs, building the quadrics, choosing
// every pair's target and filling the heap, plus one contraction and building the output. The
// simplification time is the full run to 10 faces minus that. Each is the minimum of `reps` runs.
FigureResult fig5(Context& cx) {
  FigureResult r{"gh97_fig5", "GH97 Fig. 5: running times to 10 faces", "", {}, {}};
  struct Row {
    const char *label, *file;
    double t;  // absolute pair threshold, model units (as the paper's t)
    double paper_init, paper_simplify;
  };
  std::vector<Row> rows = {
      {"Bunny", "gh_bunny_zipper.ply", 0, 3.3, 12.0},
      {"Crater Lake (stand-in: Grand Canyon 179k)", "terrain_gcanyon_179k.ply", 0, 10.6, 36.0},
      {"Cow", "gh_cow.obj", 0, 0.22, 0.69},
      {"Cube Grid", "synth_cubes_10x10.ply", 0.12, 0.25, 0.17},
      {"Foot", "gh_foot_bones.off", 0, 0.16, 0.41},
      {"Foot", "gh_foot_bones.off", 0.318, 0.43, 0.76}};
  if (cx.quick()) rows = {rows[2], rows[3], rows[5]};
  const int reps = cx.quick() ? 1 : 3;
  Table table{{"model", "faces", "t", "init (s)", "simplify (s)", "total (s)", "output faces",
               "paper init (s)", "paper simplify (s)"},
              {}};
  Plot plot{"GH97 Fig. 5: time to a 10-face approximation", "", "seconds", false, true, {}, {}, false};
  Series init{"init (ours)", {}, {}, {}, Series::Style::Bars},
      simp{"simplify (ours)", {}, {}, {}, Series::Style::Bars};
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& row = rows[i];
    const Mesh& m = cx.model(row.file);
    cx.log("fig5: " + std::string(row.file) + " t=" + num(row.t));
    SimplifyOptions o = gh97_options(10, row.t);
    double t_init = std::numeric_limits<double>::infinity(), t_total = t_init;
    std::size_t out_faces = 0;
    for (int k = 0; k < reps; ++k) {
      o.target_faces = m.face_count() - 1;
      auto t0 = std::chrono::steady_clock::now();
      simplify(m, o);
      t_init = std::min(t_init, seconds_since(t0));
      o.target_faces = 10;
      t0 = std::chrono::steady_clock::now();
      out_faces = simplify(m, o).mesh.face_count();
      t_total = std::min(t_total, seconds_since(t0));
    }
    double t_simp = std::max(0.0, t_total - t_init);
    table.rows.push_back({row.label, std::to_string(m.face_count()), num(row.t), num(t_init, "%.3f"),
                          num(t_simp, "%.3f"), num(t_total, "%.3f"), std::to_string(out_faces),
                          num(row.paper_init), num(row.paper_simplify)});
    std::string cat = std::string(row.label).substr(0, std::string(row.label).find(' ')) +
                      (row.t > 0 ? " t=" + num(row.t) : "");
    plot.categories.push_back(cat);
    init.x.push_back(double(i)), init.y.push_back(t_init);
    simp.x.push_back(double(i)), simp.y.push_back(t_simp);
    r.values[std::string(row.file) + "_t" + num(row.t) + "_total"] = t_total;
  }
  plot.series = {init, simp};
  cx.write(r, table, plot,
           "Init = a run stopped after one contraction (target = input faces - 1); simplify = full run to 10 "
           "faces minus init; minimum of " +
               std::to_string(reps) + " runs, model already in memory. Paper: SGI Indigo2, R10000 195 MHz.");
  return r;
}

// --- GH97 Fig. 6: fixed vs optimal placement on the cow ------------------------------------------------
FigureResult fig6(Context& cx) {
  FigureResult r{"gh97_fig6", "GH97 Fig. 6: fixed vs optimal vertex placement (cow, t = 0)", "", {}, {}};
  const Mesh& cow = cx.model("gh_cow.obj");
  const double diag = bounding_box(cow).diagonal();
  std::vector<std::size_t> targets = {10, 100, 500, 1000, 2000, 3000};
  const double paper_fixed[] = {0.0062, 0.00032, 2.4e-05, 5.7e-06, 1.2e-06, 3.6e-07};
  const double paper_opt[] = {0.0054, 0.00025, 1.3e-05, 3.4e-06, 7.9e-07, 2.6e-07};
  // Two configurations: as GH97 (no link-condition test) and the library default (topology kept,
  // which can stop above the target: the actual face counts are in the first column).
  Table table{{"faces (actual)", "fixed E_i", "optimal E_i", "reduction", "optimal E_i/diag^2",
               "fixed, topology kept", "optimal, topology kept", "reduction, topology kept", "paper fixed",
               "paper optimal", "paper reduction"},
              {}};
  Series sf{"fixed (endpoints/midpoint)", {}, {}, {}, Series::Style::LinePoints};
  Series so{"optimal", {}, {}, {}, Series::Style::LinePoints};
  Series pf{"paper fixed (its units)", {}, {}, {}, Series::Style::Points},
      po{"paper optimal (its units)", {}, {}, {}, Series::Style::Points};
  for (std::size_t i = 0; i < targets.size(); ++i) {
    double e[4];
    std::size_t faces[4];
    for (int k = 0; k < 4; ++k) {
      SimplifyOptions o = gh97_options(targets[i]);
      o.placement = k % 2 == 0 ? Placement::Endpoints : Placement::Optimal;
      o.preserve_topology = k >= 2;
      Mesh approx = simplify(cow, o).mesh;
      faces[k] = approx.face_count();
      e[k] = cx.E(cow, approx);
    }
    cx.log("fig6: " + std::to_string(targets[i]) + " faces: fixed " + num(e[0]) + " optimal " + num(e[1]));
    double red = e[0] > 0 ? 100 * (e[0] - e[1]) / e[0] : 0;
    double red_topo = e[2] > 0 ? 100 * (e[2] - e[3]) / e[2] : 0;
    double pred = 100 * (paper_fixed[i] - paper_opt[i]) / paper_fixed[i];
    std::string count = std::to_string(faces[0]);
    for (int k = 1; k < 4; ++k)
      if (faces[k] != faces[0]) count += "/" + std::to_string(faces[k]);
    table.rows.push_back({count, num(e[0]), num(e[1]), num(red, "%.1f%%"), num(e[1] / (diag * diag)),
                          num(e[2]), num(e[3]), num(red_topo, "%.1f%%"), num(paper_fixed[i]),
                          num(paper_opt[i]), num(pred, "%.1f%%")});
    double x = double(targets[i]);
    sf.x.push_back(x), sf.y.push_back(e[0]), so.x.push_back(x), so.y.push_back(e[1]);
    pf.x.push_back(x), pf.y.push_back(paper_fixed[i]), po.x.push_back(x), po.y.push_back(paper_opt[i]);
    r.values["fixed_" + std::to_string(targets[i])] = e[0];
    r.values["optimal_" + std::to_string(targets[i])] = e[1];
    r.values["fixed_topology_" + std::to_string(targets[i])] = e[2];
    r.values["optimal_topology_" + std::to_string(targets[i])] = e[3];
  }
  Plot plot{"GH97 Fig. 6: E_i on the cow",
            "faces",
            "E_i (mean squared distance)",
            true,
            true,
            {},
            {sf, so, pf, po},
            false};
  cx.write(
      r, table, plot,
      "E_i of GH97 §6.1 with " + std::to_string(cx.samples()) +
          " samples (seed 1), area-weighted quadrics (library default), Placement::Endpoints as 'fixed'; "
          "first columns and plot without the link-condition test (as GH97), then with it. "
          "Our cow's bounding-box diagonal is " +
          num(diag) +
          "; the paper's model units are unknown, so "
          "compare the reduction column and the relative trend.");
  return r;
}

// --- GH97 Fig. 7: E_250 of the foot as a function of the pair threshold t -----------------------------
FigureResult fig7(Context& cx) {
  FigureResult r{"gh97_fig7", "GH97 Fig. 7: E_250 of the foot vs pair threshold t", "", {}, {}};
  const Mesh& foot = cx.model("gh_foot_bones.off");
  const double diag = bounding_box(foot).diagonal();
  std::vector<double> ts = {0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.318, 0.4, 0.5, 0.6, 0.8, 1.0};
  if (cx.quick()) ts = {0, 0.318};
  Table table{{"t", "t / diag", "E_250", "faces", "virtual pairs", "components"}, {}};
  Series s{"E_250 (ours)", {}, {}, {}, Series::Style::LinePoints};
  for (double t : ts) {
    SimplifyOptions o = gh97_options(250, t);
    SimplifyResult res = simplify(foot, o);
    double e = cx.E(foot, res.mesh);
    cx.log("fig7: t=" + num(t) + " E=" + num(e));
    table.rows.push_back({num(t), num(t / diag), num(e), std::to_string(res.mesh.face_count()),
                          std::to_string(res.virtual_pairs), std::to_string(mesh_info(res.mesh).components)});
    s.x.push_back(t), s.y.push_back(e);
    r.values["E_t" + num(t)] = e;
  }
  Plot plot{"GH97 Fig. 7: E_250 on the foot",
            "pair threshold t (model units)",
            "E_250",
            false,
            false,
            {},
            {s},
            false};
  cx.write(r, table, plot,
           "Foot bones (4,204 faces, bounding-box diagonal " + num(diag) +
               "), 250-face approximations, preserve_topology off (as GH97), E_i with " +
               std::to_string(cx.samples()) +
               " samples. The paper plots E_250 for t in model units; its "
               "Fig. 17 uses t = 0.318.");
  return r;
}

// --- GH97 Figs. 15-17: clustering vs edge contraction vs pair contraction on the foot ----------------
FigureResult fig15_17(Context& cx) {
  FigureResult r{
      "gh97_fig15_17", "GH97 Figs. 15-17: clustering vs edge vs pair contraction (foot)", "", {}, {}};
  const Mesh& foot = cx.model("gh_foot_bones.off");
  MeshInfo orig = mesh_info(foot);
  struct Method {
    std::string name;
    Mesh mesh;
    std::string paper;
  };
  std::vector<Method> methods;
  ClusterOptions co;
  co.grid[0] = 11, co.grid[1] = 4, co.grid[2] = 4;  // the paper's 11 x 4 x 4 grid (long axis = x here)
  methods.push_back({"uniform clustering 11x4x4 (Fig. 15)", cluster(foot, co), "262 faces"});
  SimplifyOptions o = gh97_options(250);
  methods.push_back({"edge contraction t=0 (Fig. 16)", simplify(foot, o).mesh, "250 faces"});
  o.threshold = 0.318;
  methods.push_back(
      {"pair contraction t=0.318 (Fig. 17)", simplify(foot, o).mesh, "250 faces, 61 non-manifold edges"});
  Table table{{"method", "faces", "E_i", "components", "non-manifold edges", "paper"}, {}};
  table.rows.push_back({"original (Fig. 14)", std::to_string(foot.face_count()), "0",
                        std::to_string(orig.components), std::to_string(orig.non_manifold_edges),
                        "4,204 faces"});
  Plot plot{"GH97 Figs. 15-17: foot at ~250 faces", "", "E_i", false, false, {}, {}, false};
  Series se{"E_i", {}, {}, {}, Series::Style::Bars};
  const char* keys[] = {"cluster", "edge", "pair"};
  const char* cats[] = {"clustering", "edge contraction", "pair contraction"};
  for (std::size_t i = 0; i < methods.size(); ++i) {
    MeshInfo info = mesh_info(methods[i].mesh);
    double e = cx.E(foot, methods[i].mesh);
    cx.log("fig15-17: " + methods[i].name + " E=" + num(e));
    table.rows.push_back({methods[i].name, std::to_string(methods[i].mesh.face_count()), num(e),
                          std::to_string(info.components), std::to_string(info.non_manifold_edges),
                          methods[i].paper});
    plot.categories.push_back(cats[i]);
    se.x.push_back(double(i)), se.y.push_back(e);
    r.values[std::string(keys[i]) + "_E"] = e;
    r.values[std::string(keys[i]) + "_components"] = double(info.components);
    r.values[std::string(keys[i]) + "_non_manifold_edges"] = double(info.non_manifold_edges);
    r.values[std::string(keys[i]) + "_faces"] = double(methods[i].mesh.face_count());
  }
  plot.series = {se};
  cx.write(
      r, table, plot,
      "Components and non-manifold edges as `qem info` counts them (src/analysis/mesh_info.cpp); E_i with " +
          std::to_string(cx.samples()) + " samples.");
  return r;
}

// --- HG99 Fig. 8: optimal vs actual aspect ratio on the simplified ellipsoid ---------------------------
FigureResult hg99_fig8(Context& cx) {
  FigureResult r{
      "hg99_fig8", "HG99 Fig. 8: optimal vs actual triangle aspect ratio (ellipsoid, 800 faces)", "", {}, {}};
  const Mesh& ell = cx.model("synth_ellipsoid_11k_curv.ply");
  const double axes[3] = {1, 2, 3};
  SimplifyOptions o;
  o.target_faces = 800;
  Mesh approx = simplify(ell, o).mesh;
  Analysis a = analyze(approx);
  // HG99 §5: the optimal ratio "computed from the principal curvatures of the underlying ellipsoid at
  // the center of each triangle".
  std::vector<double> optimal(approx.face_count());
  for (std::size_t f = 0; f < approx.face_count(); ++f) {
    double c[3] = {0, 0, 0};
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c[k] += approx.positions[3 * approx.indices[3 * f + j] + k] / 3;
    double k1, k2;
    ellipsoid_curvatures(axes, c, k1, k2);
    optimal[f] = optimal_aspect_ratio(k1, k2);
  }
  double corr = stats::correlation(optimal, a.aspect);
  const double width = 0.25;
  Table table{{"optimal aspect (bucket)", "triangles", "actual mean", "actual std", "optimal mean"}, {}};
  Series pts{"triangles", optimal, a.aspect, {}, Series::Style::Points};
  Series buckets{"bucket mean +- std", {}, {}, {}, Series::Style::LinePoints};
  for (double lo = 1; lo < 3.5; lo += width) {
    std::vector<double> act, opt;
    for (std::size_t f = 0; f < optimal.size(); ++f)
      if (optimal[f] >= lo && optimal[f] < lo + width) act.push_back(a.aspect[f]), opt.push_back(optimal[f]);
    if (act.empty()) continue;
    stats::Summary sa = stats::summarize(act), so = stats::summarize(opt);
    table.rows.push_back({num(lo, "%.2f") + "-" + num(lo + width, "%.2f"), std::to_string(act.size()),
                          num(sa.mean), num(sa.stddev), num(so.mean)});
    buckets.x.push_back(so.mean), buckets.y.push_back(sa.mean), buckets.err.push_back(sa.stddev);
  }
  stats::Summary all_act = stats::summarize(a.aspect), all_opt = stats::summarize(optimal);
  r.values["correlation"] = corr;
  r.values["faces"] = double(approx.face_count());
  r.values["mean_actual"] = all_act.mean;
  r.values["mean_optimal"] = all_opt.mean;
  cx.log("hg99 fig8: correlation " + num(corr));
  Plot plot{"HG99 Fig. 8: aspect ratios, ellipsoid at " + std::to_string(approx.face_count()) + " faces",
            "theoretically optimal aspect ratio sqrt|k1/k2|",
            "actual aspect ratio",
            false,
            false,
            {},
            {pts, buckets},
            true};
  cx.write(
      r, table, plot,
      "Ellipsoid (axes 1, 2, 3; 11,280 faces) simplified to " + std::to_string(approx.face_count()) +
          " faces with the default options. Actual = Steiner-circumellipse axis ratio (HG99 §3.2); optimal = "
          "sqrt|k1/k2| (HG99 eq. 34) from the analytic curvatures at the triangle's centroid projected "
          "radially onto the ellipsoid. Pearson correlation (all triangles) = " +
          num(corr, "%.3f") + "; mean actual " + num(all_act.mean) + ", mean optimal " + num(all_opt.mean) +
          ".");
  return r;
}

}  // namespace

/// Principal curvature magnitudes of the ellipsoid x^2/a^2 + y^2/b^2 + z^2/c^2 = 1 at p (projected
/// radially onto it first), from the implicit-surface formulas with gradient g and Hessian
/// H = diag(2/a^2, 2/b^2, 2/c^2): K = g^T adj(H) g / |g|^4, mean = (|g|^2 tr H - g^T H g) / (2 |g|^3).
void ellipsoid_curvatures(const double axes[3], const double p[3], double& k1, double& k2) {
  double s = 0;
  for (int i = 0; i < 3; ++i) s += p[i] * p[i] / (axes[i] * axes[i]);
  double q[3], g[3], h[3];
  for (int i = 0; i < 3; ++i) {
    q[i] = p[i] / std::sqrt(s);
    h[i] = 2 / (axes[i] * axes[i]);
    g[i] = h[i] * q[i];
  }
  double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
  double gauss =
      (g[0] * g[0] * h[1] * h[2] + g[1] * g[1] * h[0] * h[2] + g[2] * g[2] * h[0] * h[1]) / (g2 * g2);
  double mean = (g2 * (h[0] + h[1] + h[2]) - (g[0] * g[0] * h[0] + g[1] * g[1] * h[1] + g[2] * g[2] * h[2])) /
                (2 * g2 * std::sqrt(g2));
  double d = std::sqrt(std::max(0.0, mean * mean - gauss));
  k1 = mean + d, k2 = mean - d;
}

std::vector<FigureResult> run(const Options& options) {
  for (const auto& id : options.only)
    if (std::find(kFigures.begin(), kFigures.end(), id) == kFigures.end())
      throw Error("reproduce: unknown figure '" + id + "'");
  Context cx(options);
  std::vector<FigureResult> out;
  auto want = [&](const std::string& id) {
    return options.only.empty() ||
           std::find(options.only.begin(), options.only.end(), id) != options.only.end();
  };
  if (want("gh97_fig5")) out.push_back(fig5(cx));
  if (want("gh97_fig6")) out.push_back(fig6(cx));
  if (want("gh97_fig7")) out.push_back(fig7(cx));
  if (want("gh97_fig15_17")) out.push_back(fig15_17(cx));
  if (want("hg99_fig8")) out.push_back(hg99_fig8(cx));
  std::string summary = "# Reproduced figures\n\n";
  for (const auto& f : out) summary += f.markdown + "\n![" + f.id + "](" + f.id + ".svg)\n\n";
  io::write_file_atomic((fs::path(options.out_dir) / "summary.md").string(), summary);
  return out;
}

}  // namespace qem::reproduce
