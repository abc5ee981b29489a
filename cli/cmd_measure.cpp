// `qem measure`: the GH97 §6.1 approximation error between an original and a simplified mesh
// (E_i over area-uniform samples of both surfaces, Hausdorff, RMS, mean), as src/measure computes it.
// --json prints one line with the field names of the benchmark's metric tool, and the attribute
// error (uv_rms, normal_rms_deg, color_rms, seam_cracks) with those of its attr_metric.py.
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "cli_util.h"
#include "command.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/measure.h"

namespace qem::cli {

namespace {

struct MeasureArgs {
  std::string original, approx, per_vertex;
  MeasureOptions options;
  bool json = false;
};

void print_json(const MeasureArgs& a, const Mesh& original, const Mesh& approx, const MeasureResult& r,
                double seconds) {
  auto num = [](double x) { return json_number(x); };
  std::string s = "{";
  s += "\"original\":" + json_string(a.original) + ",\"approx\":" + json_string(a.approx);
  s += ",\"orig_faces\":" + std::to_string(original.face_count());
  s += ",\"approx_faces\":" + std::to_string(approx.face_count());
  s += ",\"orig_degenerate_faces\":" + std::to_string(r.degenerate_original);
  s += ",\"approx_degenerate_faces\":" + std::to_string(r.degenerate_approx);
  s += ",\"orig_area\":" + num(r.area_original) + ",\"approx_area\":" + num(r.area_approx);
  s += ",\"bbox_diag\":" + num(r.bbox_diag);
  s += ",\"samples_orig\":" + std::to_string(r.samples_original);
  s += ",\"samples_approx\":" + std::to_string(r.samples_approx);
  s += ",\"seed\":" + std::to_string(a.options.seed);
  s += ",\"E\":" + num(r.E) + ",\"E_rel\":" + num(r.E_rel);
  s += ",\"rms\":" + num(r.rms) + ",\"rms_rel\":" + num(r.rms_rel);
  s += ",\"hausdorff\":" + num(r.hausdorff) + ",\"hausdorff_rel\":" + num(r.hausdorff_rel);
  s += ",\"h_o2a\":" + num(r.h_original_to_approx) + ",\"h_a2o\":" + num(r.h_approx_to_original);
  s += ",\"mean_o2a\":" + num(r.mean_original_to_approx) + ",\"mean_a2o\":" + num(r.mean_approx_to_original);
  s += ",\"rms_o2a\":" + num(r.rms_original_to_approx) + ",\"rms_a2o\":" + num(r.rms_approx_to_original);
  s += ",\"mean\":" + num(r.mean) + ",\"mean_rel\":" + num(r.mean_rel);
  // The attribute error under attr_metric.py's names; null for an attribute either mesh lacks.
  auto opt = [&](const std::optional<double>& x) { return x ? num(*x) : std::string("null"); };
  s += ",\"uv_rms\":" + opt(r.uv_rms) + ",\"normal_rms_deg\":" + opt(r.normal_rms_deg);
  s += ",\"color_rms\":" + opt(r.color_rms);
  s += std::string(",\"attr_by_material\":") + (r.attributes_by_material ? "true" : "false");
  s += ",\"cracks_in\":" + std::to_string(r.cracks_in) + ",\"cracks_out\":" + std::to_string(r.cracks_out);
  s += ",\"seam_cracks\":" + std::to_string(r.seam_cracks);
  char t[32];
  std::snprintf(t, sizeof t, "%.3f", seconds);
  s += ",\"metric_s\":" + std::string(t) + "}";
  std::printf("%s\n", s.c_str());
}

void print_table(const MeasureArgs& a, const Mesh& original, const Mesh& approx, const MeasureResult& r,
                 double seconds) {
  std::printf("original       %s (%zu faces, area %.6g)\n", a.original.c_str(), original.face_count(),
              r.area_original);
  std::printf("approximation  %s (%zu faces, area %.6g", a.approx.c_str(), approx.face_count(),
              r.area_approx);
  if (r.degenerate_approx) std::printf(", %zu zero-area faces ignored", r.degenerate_approx);
  std::printf(")\n");
  std::printf("samples        %zu on the original + %zu on the approximation (seed %llu)\n",
              r.samples_original, r.samples_approx, static_cast<unsigned long long>(a.options.seed));
  std::printf("bbox diagonal  %.6g (of the original; \"relative\" divides by it, E by its square)\n\n",
              r.bbox_diag);
  std::printf("%-28s %14s %14s\n", "", "absolute", "relative");
  auto row = [](const char* name, double abs, double rel) {
    std::printf("%-28s %14.6e %14.6e\n", name, abs, rel);
  };
  const double d = r.bbox_diag;
  row("E (GH97 6.1, mean sq dist)", r.E, r.E_rel);
  row("RMS = sqrt(E)", r.rms, r.rms_rel);
  row("mean distance", r.mean, r.mean_rel);
  row("Hausdorff (symmetric)", r.hausdorff, r.hausdorff_rel);
  row("  original -> approx max", r.h_original_to_approx, r.h_original_to_approx / d);
  row("  approx -> original max", r.h_approx_to_original, r.h_approx_to_original / d);
  row("  original -> approx mean", r.mean_original_to_approx, r.mean_original_to_approx / d);
  row("  approx -> original mean", r.mean_approx_to_original, r.mean_approx_to_original / d);
  row("  original -> approx RMS", r.rms_original_to_approx, r.rms_original_to_approx / d);
  row("  approx -> original RMS", r.rms_approx_to_original, r.rms_approx_to_original / d);
  std::printf("\nattributes at the %zu samples on the original, approximation at the closest point%s\n",
              r.samples_original, r.attributes_by_material ? " of the same material" : "");
  auto attribute = [](const char* name, const std::optional<double>& x, const char* unit) {
    if (x)
      std::printf("  %-26s %14.6e %s\n", name, *x, unit);
    else
      std::printf("  %-26s %14s\n", name, "-");  // absent from either mesh
  };
  attribute("UV RMS", r.uv_rms, "(UV units)");
  attribute("normal RMS angle", r.normal_rms_deg, "(degrees)");
  attribute("colour RMS", r.color_rms, "(RGBA, 0..1)");
  std::printf("  %-26s %14zu (boundary edges welded by position: %zu original, %zu approximation)\n",
              "seam cracks", r.seam_cracks, r.cracks_in, r.cracks_out);
  std::printf("\ntime           %.3f s\n", seconds);
}

int run_measure(MeasureArgs& a) {
  const Stopwatch clock;
  if (!a.per_vertex.empty() && format_from_extension(a.per_vertex) != FileFormat::Ply)
    throw Error(a.per_vertex + ": --per-vertex writes a PLY file (the only format with vertex properties)");
  const Mesh original = load_input(a.original);
  LoadReport approx_report;
  Mesh approx = load_input(a.approx, {}, &approx_report);
  a.options.per_vertex = !a.per_vertex.empty();
  MeasureResult r = measure(original, approx, a.options);
  const double seconds = clock.seconds();
  if (a.json)
    print_json(a, original, approx, r, seconds);
  else
    print_table(a, original, approx, r, seconds);
  if (!a.per_vertex.empty()) {
    approx.vertex_properties.clear();
    approx.vertex_properties.push_back({"distance", std::move(r.vertex_distance)});
    SaveOptions save;
    save.double_precision = approx_report.double_precision;  // a double PLY stays double
    save_mesh(a.per_vertex, approx, save);
    if (!a.json)
      std::printf("per-vertex     %s (property `distance`: approx vertex -> original)\n",
                  a.per_vertex.c_str());
  }
  return 0;
}

const bool registered = register_command(30, [](CLI::App& app) -> std::function<int()> {
  auto args = std::make_shared<MeasureArgs>();
  MeasureOptions& o = args->options;
  CLI::App* cmd = app.add_subcommand(
      "measure",
      "Approximation error between an original and a simplified mesh: GH97 6.1 E (mean squared distance "
      "over points sampled uniformly by area on both surfaces), RMS, mean and Hausdorff distance; with "
      "attributes, the UV, normal and colour error at the closest points and the cracks opened along seams");
  cmd->add_option("original", args->original, "The original mesh (OBJ, PLY, STL, OFF, glTF)")->required();
  cmd->add_option("approx", args->approx, "The approximation (simplified mesh)")->required();
  cmd->add_option("--samples", o.samples,
                  "Sample points in total, split between the two surfaces in proportion to their areas")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t(1), std::size_t(1) << 40));
  cmd->add_option("--seed", o.seed, "Seed of the xoshiro256** sample generator (same seed, same numbers)")
      ->capture_default_str();
  cmd->add_option("--threads", o.threads, "Worker threads, 0 = all cores (the result does not depend on it)")
      ->capture_default_str();
  cmd->add_flag("!--no-vertices", o.include_vertices,
                "Hausdorff over the samples only (by default each surface's vertices are included)");
  cmd->add_flag("--json", args->json,
                "Print one JSON line (field names as the benchmark's metric tool) instead of a table");
  cmd->add_option("--per-vertex", args->per_vertex,
                  "Write the approximation to this PLY with a per-vertex `distance` property "
                  "(distance of each vertex to the original; `qem render` shows it as a heat map)");
  return [args] { return run_measure(*args); };
});

}  // namespace

}  // namespace qem::cli
