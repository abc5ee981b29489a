// `qem lod INPUT OUTDIR --ratios 0.5,0.25,0.1`: an LOD chain from ONE simplification (GH97 §3:
// a single run yields M_n ... M_g). The run goes to the coarsest level with a contraction record;
// every level is then a prefix of that record, rebuilt in one pass, and each file is
// byte-identical to `qem simplify INPUT FILE --faces <level target>` with the same options
// (with a refit, the default's light one or --refit's, each level is refitted to the input after
// it is rebuilt, as simplify refits its output).
// Writes the levels and a manifest.json that `qem view` shows as a chain with a slider. A glTF
// input gives glTF levels by default: one whole document per level (run_lod_gltf says why).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "algorithm_options.h"
#include "cli_util.h"
#include "command.h"
#include "io/io_common.h"
#include "qem/error.h"
#include "qem/gltf.h"
#include "qem/gltf_simplify.h"
#include "qem/io.h"
#include "qem/progressive.h"
#include "qem/refit.h"
#include "refit/refit_after_simplify.h"
#include "qem/simplify.h"

namespace qem::cli {
namespace {

struct LodArgs {
  std::string input, outdir, format, name;  // format "": ply, or glb for a glTF input
  std::vector<double> ratios;
  std::vector<std::size_t> faces;
  AlgorithmArgs algorithm;
  bool ascii = false, json = false, quiet = false;
  bool double_values = false;  // --double
  bool per_mesh = false;       // --per-mesh (glTF documents)
};

/// A glTF input written as glTF: one whole document per level (each a .glb / .gltf that any viewer
/// opens, with the materials, textures, nodes, skins and animations of the input), rather than one
/// file with MSFT_lod, which few loaders read and which ties every level to one download. Each
/// level is simplify_document on a fresh copy of the input, so each file is what `qem simplify
/// INPUT FILE --faces <level target>` writes (ratios are of the simplifiable primitives' faces).
int run_lod_gltf(const LodArgs& a, const SimplifyOptions& opt) {
  namespace fs = std::filesystem;
  Stopwatch total;
  const double cpu_start = process_cpu_seconds();
  const GltfDocument input = GltfDocument::load(a.input);  // read once: a bad file fails before any level
  std::size_t base_faces = 0, base_vertices = 0;
  for (const GltfPrimitiveInfo& p : input.primitives())
    if (p.simplifiable) base_faces += p.face_count, base_vertices += p.vertex_count;
  std::vector<std::size_t> targets = a.faces;
  for (double r : a.ratios) targets.push_back(std::size_t(std::floor(r * double(base_faces))));
  std::sort(targets.begin(), targets.end(), std::greater<>());  // finest first, as the manifest lists them
  targets.erase(std::unique(targets.begin(), targets.end()), targets.end());
  const std::string bytes = input.serialize(true);  // each level starts from a copy of the document
  std::error_code ec;
  fs::create_directories(a.outdir, ec);
  if (ec) throw Error(a.outdir + ": cannot create the folder: " + ec.message());
  const std::string stem = a.name.empty() ? fs::path(a.input).stem().string() : a.name;
  GltfSimplifyOptions gltf_options;
  gltf_options.per_primitive = a.per_mesh;
  gltf_options.threads = a.algorithm.threads;
  std::string manifest = "{\n  \"generator\": \"qem lod\",\n  \"source\": " +
                         json_string(fs::path(a.input).filename().string()) +
                         ",\n  \"input_faces\": " + std::to_string(base_faces) +
                         ",\n  \"input_vertices\": " + std::to_string(base_vertices) + ",\n  \"levels\": [\n";
  for (std::size_t i = 0; i < targets.size(); ++i) {
    GltfDocument doc = GltfDocument::parse(bytes, a.input);
    SimplifyOptions level = opt;
    level.target_ratio = 0, level.target_faces = std::max<std::size_t>(1, targets[i]);
    const GltfSimplifyReport r = simplify_document(doc, level, gltf_options);
    const std::string file = stem + "_lod" + std::to_string(i) + "." + a.format;
    doc.save((fs::path(a.outdir) / file).string());
    std::size_t vertices = 0;
    for (const GltfPrimitiveInfo& p : doc.primitives()) vertices += p.vertex_count;
    manifest += "    {\"path\": " + json_string(file) + ", \"faces\": " + std::to_string(r.faces_out) +
                ", \"vertices\": " + std::to_string(vertices) +
                ", \"error\": " + json_number(r.max_world_error) +
                ", \"target_faces\": " + std::to_string(targets[i]) +
                ", \"primitives_simplified\": " + std::to_string(r.simplified) + "}" +
                (i + 1 < targets.size() ? ",\n" : "\n");
    if (!a.quiet)
      std::fprintf(
          stderr,
          "qem: level %zu faces (target %zu; %zu primitives simplified), max error %.4g in world units\n",
          r.faces_out, targets[i], r.simplified, r.max_world_error);
  }
  manifest += "  ]\n}\n";
  io::write_file_atomic((fs::path(a.outdir) / "manifest.json").string(), manifest);
  for (const std::string& n : input.notes()) std::fprintf(stderr, "qem: note: %s\n", n.c_str());
  if (a.json)
    std::printf(
        "{\"tool\":\"qem lod\",\"format\":\"gltf\",\"in_faces\":%zu,\"levels\":%zu,\"cpu_s\":%s,"
        "\"total_s\":%s,\"peak_rss_mb\":%s}\n",
        base_faces, targets.size(), json_number(process_cpu_seconds() - cpu_start).c_str(),
        json_number(total.seconds()).c_str(), json_number(peak_rss_mb()).c_str());
  if (!a.quiet)
    std::fprintf(stderr, "qem: %zu glTF levels, each a whole document, %.3f s total\n", targets.size(),
                 total.seconds());
  return 0;
}

int run_lod_mesh(const LodArgs& a);

int run_lod(const LodArgs& a) {
  if (a.ratios.empty() == a.faces.empty()) throw Error("give the levels with either --ratios or --faces");
  for (double r : a.ratios)
    if (!(r >= 0 && r <= 1)) throw Error("--ratios: every ratio must be in [0, 1], got " + json_number(r));
  const bool gltf_input = format_from_extension(a.input) == FileFormat::Gltf;
  LodArgs args = a;
  if (args.format.empty()) args.format = gltf_input ? "glb" : "ply";
  const bool gltf_levels = args.format == "glb" || args.format == "gltf";
  if (gltf_levels && !gltf_input)
    throw Error("--format " + args.format +
                ": glTF levels are made from a glTF input (.glb / .gltf), whose "
                "document they keep; give --format ply, obj, stl or off for this input");
  if (a.per_mesh && !gltf_levels) throw Error("--per-mesh applies to glTF levels (a .glb / .gltf input)");
  if (gltf_levels) {
    // A scene's shared error budget needs a face target to share; 0 ("as far as the checks allow")
    // is taken per mesh file only.
    for (double r : a.ratios)
      if (r == 0) throw Error("--ratios: glTF levels need ratios above 0, got 0");
    for (std::size_t f : a.faces)
      if (f == 0) throw Error("--faces: glTF levels need face counts above 0, got 0");
    SimplifyOptions opt = to_simplify_options(a.algorithm);
    opt.target_faces = 1;
    check_options(opt);
    opt.refit_rounds = attribute_refit_rounds(a.algorithm, opt);  // as `qem simplify` on a document
    opt.far_repair = far_repair_wanted(a.algorithm, opt);
    return run_lod_gltf(args, opt);
  }
  return run_lod_mesh(args);
}

int run_lod_mesh(const LodArgs& a) {
  Stopwatch total;
  const double cpu_start = process_cpu_seconds();

  LoadReport report;
  Mesh mesh = load_input(a.input, to_load_options(a.algorithm), &report);

  // One run to the coarsest level, recorded. Ratios are taken of the faces the run starts from
  // (degenerate and duplicate input faces dropped), exactly as `qem simplify --ratio` does.
  SimplifyOptions opt = to_simplify_options(a.algorithm);
  std::vector<std::uint8_t> lock;  // --lock-property: outlives the runs, as vertex_lock must
  apply_lock_property(a.algorithm, a.input, mesh, lock, opt);
  // A refit (the default's, or --refit's): each level is refitted below, as simplify refits its
  // output; the run itself only records the contractions.
  const RefitOptions refit = refit_options_for(opt);
  const SimplifyOptions refit_as = opt;  // each level's refit follows its reduction (refit_levels)
  opt.refit_rounds = 0;
  opt.far_repair = false;  // the levels are the recorded contractions', repaired after their refit
  ContractionRecorder recorder;
  if (!a.faces.empty())
    opt.target_faces = *std::min_element(a.faces.begin(), a.faces.end());
  else
    opt.target_ratio = *std::min_element(a.ratios.begin(), a.ratios.end());
  // A level of 0 faces (or ratio 0) is the mesh as far as the checks allow.
  opt.as_far_as_possible = opt.target_faces == 0 && opt.target_ratio == 0;
  // A record replays positions and faces only: with attributes (UVs, normals, colours) or face
  // materials each level is a run of its own, which carries them.
  const bool attributes = !mesh.attributes.empty() || !mesh.face_materials.empty();
  const double cpu_simplify0 = process_cpu_seconds();
  const SimplifyResult result = simplify(mesh, opt, attributes ? nullptr : &recorder);
  const double simplify_cpu = process_cpu_seconds() - cpu_simplify0;
  const double cpu_replay0 = process_cpu_seconds();
  // A record replays one side of a sheet made two-sided by reversed copies of its faces (it holds
  // the contractions, not the twins put back after them: SimplifyOptions::two_sided); such an
  // input's levels are runs of their own too.
  const bool own_runs = attributes || (opt.two_sided != TwoSided::None && result.dropped_duplicate_faces > 0);
  const Record record = own_runs ? Record{} : make_record(mesh, recorder.log);
  const std::size_t base_faces = own_runs ? result.input_faces : record.base.face_count();
  const std::size_t base_vertices = own_runs ? result.input_vertices : record.base.vertex_count();
  std::vector<std::size_t> targets = a.faces;
  for (double r : a.ratios) targets.push_back(std::size_t(std::floor(r * double(base_faces))));
  std::sort(targets.begin(), targets.end(), std::greater<>());  // finest first, as the manifest lists them
  targets.erase(std::unique(targets.begin(), targets.end()), targets.end());
  std::vector<ReplayLevel> levels;
  if (!own_runs) levels = replay_levels(record, targets);
  for (std::size_t target : own_runs ? targets : std::vector<std::size_t>{}) {
    SimplifyOptions level = opt;
    level.target_ratio = 0, level.target_faces = target, level.as_far_as_possible = target == 0;
    // Refitted in the run, which holds its seams (simplify.cpp): the chain's refit below sees no wedges.
    level.refit_rounds = refit.rounds, level.refit_points_per_vertex = refit.points_per_vertex;
    level.refit_rounds = attribute_refit_rounds(a.algorithm, level, mesh);
    level.far_repair = far_repair_wanted(a.algorithm, level);
    SimplifyResult r = simplify(mesh, level);
    r.mesh.material_names = mesh.material_names, r.mesh.material_library = mesh.material_library;
    levels.push_back({std::move(r.mesh), target, r.contractions, r.max_error});
  }
  if (refit.rounds > 0 && !own_runs) refit_levels(mesh, levels, refit_as, result.input_vertices);
  const double replay_cpu = process_cpu_seconds() - cpu_replay0;

  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(a.outdir, ec);
  if (ec) throw Error(a.outdir + ": cannot create the folder: " + ec.message());
  const std::string stem = a.name.empty() ? fs::path(a.input).stem().string() : a.name;
  SaveOptions save;
  save.binary = !a.ascii;
  save.double_precision = a.double_values || report.double_precision;
  save.format = format_from_extension("x." + a.format);
  const double cpu_write0 = process_cpu_seconds();
  std::string manifest = "{\n  \"generator\": \"qem lod\",\n  \"source\": " +
                         json_string(fs::path(a.input).filename().string()) +
                         ",\n  \"input_faces\": " + std::to_string(base_faces) +
                         ",\n  \"input_vertices\": " + std::to_string(base_vertices) + ",\n  \"levels\": [\n";
  for (std::size_t i = 0; i < levels.size(); ++i) {
    const ReplayLevel& l = levels[i];
    const std::string file = stem + "_lod" + std::to_string(i) + "." + a.format;
    save_mesh((fs::path(a.outdir) / file).string(), l.mesh, save);
    manifest +=
        "    {\"path\": " + json_string(file) + ", \"faces\": " + std::to_string(l.mesh.face_count()) +
        ", \"vertices\": " + std::to_string(l.mesh.vertex_count()) +
        ", \"error\": " + json_number(l.max_error) + ", \"target_faces\": " + std::to_string(l.target_faces) +
        ", \"contractions\": " + std::to_string(l.contractions) + "}" +
        (i + 1 < levels.size() ? ",\n" : "\n");
  }
  manifest += "  ]\n}\n";
  io::write_file_atomic((fs::path(a.outdir) / "manifest.json").string(), manifest);
  const double write_cpu = process_cpu_seconds() - cpu_write0;

  if (a.json)
    std::printf(
        "{\"tool\":\"qem lod\",\"in_faces\":%zu,\"levels\":%zu,\"simplify_cpu_s\":%s,\"replay_cpu_s\":%s,"
        "\"write_cpu_s\":%s,\"cpu_s\":%s,\"total_s\":%s,\"peak_rss_mb\":%s}\n",
        base_faces, levels.size(), json_number(simplify_cpu).c_str(), json_number(replay_cpu).c_str(),
        json_number(write_cpu).c_str(), json_number(process_cpu_seconds() - cpu_start).c_str(),
        json_number(total.seconds()).c_str(), json_number(peak_rss_mb()).c_str());
  if (!a.quiet) {
    for (const ReplayLevel& l : levels)
      std::fprintf(stderr, "qem: level %zu faces, %zu vertices, max error %.4g\n", l.mesh.face_count(),
                   l.mesh.vertex_count(), l.max_error);
    std::fprintf(stderr, "qem: %zu levels from %s (%s), simplify %.3f s + %s %.3f s CPU, %.3f s total\n",
                 levels.size(), own_runs ? "a run each" : "one run", result.stop_detail.c_str(), simplify_cpu,
                 own_runs ? "levels" : "replay", replay_cpu, total.seconds());
  }
  return 0;
}

const bool registered = register_command(13, [](CLI::App& app) {
  auto args = std::make_shared<LodArgs>();
  CLI::App* sub = app.add_subcommand(
      "lod",
      "Write an LOD chain from a single recorded simplification, with a manifest for `qem view`; a glTF "
      "input gives one whole glTF document per level");
  sub->add_option("input", args->input, "Input mesh (.obj .ply .stl .off .glb .gltf)")->required();
  sub->add_option("outdir", args->outdir, "Folder for the levels and manifest.json (created if needed)")
      ->required();
  auto* ratios =
      sub->add_option("--ratios", args->ratios,
                      "Levels as fractions of the input faces (glTF: of its simplifiable primitives' faces), comma "
                      "separated (e.g. 0.5,0.25,0.1); 0 = as far as the checks allow (not for glTF levels)")
          ->delimiter(',');
  sub->add_option("--faces,-f", args->faces, "Levels as face counts, comma separated (e.g. 50000,10000,1000); 0 = as far as the checks allow")
      ->delimiter(',')
      ->excludes(ratios);
  sub->add_option("--format", args->format,
                  "File format of the levels (default: glb for a .glb / .gltf input, ply otherwise). glTF "
                  "levels are whole documents, one file per level, each with the input's materials, "
                  "textures, nodes, skins and animations (docs/attributes.md)")
      ->check(CLI::IsMember({"ply", "obj", "stl", "off", "glb", "gltf"}));
  sub->add_option("--name", args->name,
                  "File name stem of the levels: <name>_lod<i>.<ext> (default: input's stem)");
  add_algorithm_options(sub, args->algorithm);
  sub->add_flag("--per-mesh", args->per_mesh,
                "glTF: apply each level's target to every primitive on its own instead of the scene");
  sub->add_flag("--ascii", args->ascii, "Write PLY / STL as text instead of binary");
  sub->add_flag("--double", args->double_values, kDoubleOutputHelp);
  sub->add_flag("--json", args->json, "Print one JSON line with CPU timings and memory on stdout");
  sub->add_flag("--quiet,-q", args->quiet, "No summary on stderr");
  return [args] { return run_lod(*args); };
});

}  // namespace
}  // namespace qem::cli
