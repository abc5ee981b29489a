// `qem analyze`: HG99 §4-5 shape analysis (triangle aspect ratios, quadric eigen-structure and the
// curvature it implies, optimal aspect ratio from known curvatures) and the GH97 pictures of the
// error ellipsoids (Fig. 11) and valid pairs (Fig. 19).
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "analysis/analyze_stats.h"
#include "cli_util.h"
#include "command.h"
#include "io/io_common.h"
#include "qem/analyze.h"
#include "qem/error.h"
#include "qem/io.h"

namespace qem::cli {

namespace {

struct AnalyzeArgs {
  std::string mesh, triangles_csv, vertices_csv, ellipsoids, pairs;
  double threshold_rel = 0, ellipsoid_scale = 1;
  bool json = false;
};

void append(std::string& out, double x) {
  if (std::isfinite(x))
    io::append_number(out, x);
  else
    out += x > 0 ? "inf" : (x < 0 ? "-inf" : "nan");
}

void write_triangles(const std::string& path, const Mesh& mesh, const Analysis& a) {
  std::string out = "face,area,aspect,optimal_aspect\n";
  for (std::size_t f = 0; f < a.face_count(); ++f) {
    io::append_uint(out, f);
    out += ',';
    append(out, a.area[f]);
    out += ',';
    append(out, a.aspect[f]);
    out += ',';
    if (!a.optimal_aspect.empty()) append(out, a.optimal_aspect[f]);
    out += '\n';
  }
  (void)mesh;
  io::write_file_atomic(path, out);
}

void write_vertices(const std::string& path, const Mesh& mesh, const Analysis& a) {
  const VertexProperty* k1 = mesh.find_property("k1");
  const VertexProperty* k2 = mesh.find_property("k2");
  std::string out =
      "vertex,valence,lambda_min,lambda_mid,lambda_max,e_min_x,e_min_y,e_min_z,e_mid_x,e_mid_y,e_mid_z,"
      "normal_x,normal_y,normal_z,k_min_est,k_mid_est,curvature_ratio_est,quadric_ratio";
  if (k1 && k2) out += ",k1,k2";
  out += '\n';
  for (std::size_t v = 0; v < a.vertex_count(); ++v) {
    io::append_uint(out, v);
    out += ',';
    io::append_uint(out, a.valence[v]);
    for (int i = 0; i < 3; ++i) out += ',', append(out, a.eigenvalues[3 * v + i]);
    for (int i = 0; i < 9; ++i) out += ',', append(out, a.eigenvectors[9 * v + i]);
    for (int i = 0; i < 2; ++i) out += ',', append(out, a.curvature[2 * v + i]);
    for (int i = 0; i < 2; ++i) out += ',', append(out, a.quadric_ratio[2 * v + i]);
    if (k1 && k2) out += ',', append(out, k1->values[v]), out += ',', append(out, k2->values[v]);
    out += '\n';
  }
  io::write_file_atomic(path, out);
}

std::string summary_json(const char* name, const stats::Summary& s) {
  return std::string("\"") + name + "\":{\"count\":" + std::to_string(s.count) +
         ",\"mean\":" + json_number(s.mean) + ",\"std\":" + json_number(s.stddev) +
         ",\"min\":" + json_number(s.min) + ",\"median\":" + json_number(s.median) +
         ",\"max\":" + json_number(s.max) + "}";
}

void print_summary(const char* name, const stats::Summary& s) {
  std::printf("%-30s n=%-8zu mean %-10.4g std %-10.4g min %-10.4g median %-10.4g max %.4g\n", name, s.count,
              s.mean, s.stddev, s.min, s.median, s.max);
}

int run_analyze(const AnalyzeArgs& args) {
  LoadOptions lo;
  lo.keep_vertex_properties = true;
  const Mesh mesh = load_input(args.mesh, lo);
  const Analysis a = analyze(mesh);

  stats::Summary aspect = stats::summarize(a.aspect);
  std::vector<double> kmin, kmid, cratio, qratio;
  for (std::size_t v = 0; v < a.vertex_count(); ++v) {
    if (a.valence[v] == 0) continue;
    kmin.push_back(a.curvature[2 * v]);
    kmid.push_back(a.curvature[2 * v + 1]);
    cratio.push_back(a.quadric_ratio[2 * v]);
    qratio.push_back(a.quadric_ratio[2 * v + 1]);
  }
  stats::Summary s_kmin = stats::summarize(kmin), s_kmid = stats::summarize(kmid);
  stats::Summary s_cr = stats::summarize(cratio), s_qr = stats::summarize(qratio);
  const bool has_optimal = !a.optimal_aspect.empty();
  stats::Summary optimal = stats::summarize(a.optimal_aspect);
  double corr = has_optimal ? stats::correlation(a.optimal_aspect, a.aspect) : 0;

  if (args.json) {
    std::string s = "{\"mesh\":\"" + args.mesh + "\",\"faces\":" + std::to_string(mesh.face_count()) +
                    ",\"vertices\":" + std::to_string(mesh.vertex_count()) + "," +
                    summary_json("aspect", aspect) + "," + summary_json("k_min_est", s_kmin) + "," +
                    summary_json("k_mid_est", s_kmid) + "," + summary_json("curvature_ratio_est", s_cr) +
                    "," + summary_json("quadric_ratio", s_qr);
    if (has_optimal)
      s += "," + summary_json("optimal_aspect", optimal) +
           ",\"correlation_optimal_actual\":" + json_number(corr);
    std::printf("%s}\n", s.c_str());
  } else {
    std::printf("mesh %s: %zu vertices, %zu faces\n", args.mesh.c_str(), mesh.vertex_count(),
                mesh.face_count());
    print_summary("triangle aspect ratio", aspect);
    print_summary("|k| along e_min (estimate)", s_kmin);
    print_summary("|k| along e_mid (estimate)", s_kmid);
    print_summary("|k_mid/k_min| (estimate)", s_cr);
    print_summary("sqrt(lambda_mid/lambda_min)", s_qr);
    if (has_optimal) {
      print_summary("optimal aspect sqrt|k1/k2|", optimal);
      std::printf("correlation(optimal, actual aspect) = %.4f\n", corr);
    }
  }
  if (!args.triangles_csv.empty()) write_triangles(args.triangles_csv, mesh, a);
  if (!args.vertices_csv.empty()) write_vertices(args.vertices_csv, mesh, a);
  if (!args.ellipsoids.empty()) save_mesh(args.ellipsoids, quadric_ellipsoids(mesh, a, args.ellipsoid_scale));
  if (!args.pairs.empty()) {
    double t = args.threshold_rel * bounding_box(mesh).diagonal();
    std::size_t edges = 0;
    auto pairs = valid_pairs(mesh, t, &edges);
    save_pairs_obj(args.pairs, mesh, pairs, edges);
    if (!args.json)
      std::printf("valid pairs: %zu edges + %zu non-edge pairs closer than t = %.6g -> %s\n", edges,
                  pairs.size() - edges, t, args.pairs.c_str());
  }
  return 0;
}

const bool registered = register_command(45, [](CLI::App& app) -> std::function<int()> {
  auto args = std::make_shared<AnalyzeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "analyze",
      "Shape analysis after HG99 4-5: triangle aspect ratios (least-area ellipse), eigen-decomposition of "
      "each "
      "vertex's area-weighted quadric, the principal curvatures it implies, and (with k1, k2 PLY vertex "
      "properties) the optimal aspect ratio sqrt|k1/k2| per triangle");
  cmd->add_option("mesh", args->mesh, "The mesh to analyse (OBJ, PLY, STL, OFF)")->required();
  cmd->add_flag("--json", args->json, "Print one JSON line of summary statistics instead of a table");
  cmd->add_option("--triangles", args->triangles_csv, "Write per-triangle CSV: area, aspect, optimal_aspect");
  cmd->add_option(
      "--vertices", args->vertices_csv,
      "Write per-vertex CSV: quadric eigenvalues and eigenvectors, curvature estimates (and k1, k2)");
  cmd->add_option("--ellipsoids", args->ellipsoids,
                  "Write the quadric level-set ellipsoids of every vertex as one mesh (GH97 Fig. 11)");
  cmd->add_option("--ellipsoid-scale", args->ellipsoid_scale, "Size factor of the ellipsoids")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--pairs", args->pairs,
                  "Write the valid pairs as OBJ `l` lines, groups `edges` and `non_edges` (GH97 Fig. 19)");
  cmd->add_option("--threshold-rel", args->threshold_rel,
                  "Pair threshold t for --pairs, as a fraction of the bounding-box diagonal (0 = edges only)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  return [args] { return run_analyze(*args); };
});

}  // namespace

}  // namespace qem::cli
