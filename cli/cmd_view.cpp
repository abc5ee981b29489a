// `qem view`: shows meshes in a local web page (three.js, bundled in web/dist): one mesh, an LOD
// chain walked by a slider, or an original/simplified pair side by side; an error heat map when a
// mesh has a per-vertex `distance` property. Models are drawn with their normals, texture
// coordinates, colours and materials (OBJ .mtl textures); glTF files are shown as the document
// itself (materials, skins, animations). `--export DIR` writes the same page to a folder.
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/measure.h"
#include "qem/progressive.h"
#include "view/http_server.h"
#include "view/lod_manifest.h"
#include "view/model_assets.h"
#include "view/scene.h"
#include "view/web_assets.h"

namespace qem::cli {

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop.store(true); }

struct ViewArgs {
  std::vector<std::string> inputs;
  bool chain = false, compare = false;
  int port = 8765;
  std::string export_dir, title;
  bool measure = true;
  std::size_t samples = 200000;
};

// True when `path` starts with the magic of a contraction record (docs/record-format.md).
bool is_record_file(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  char magic[8] = {};
  const bool ok = std::fread(magic, 1, sizeof magic, f) == sizeof magic;
  std::fclose(f);
  return ok && std::memcmp(magic, "QEMREC\x1a\n", sizeof magic) == 0;
}

// A record becomes a chain (GH97 §3: one run holds M_n ... M_g): the original and then halving
// face counts down to the record's final mesh, all replayed in one pass.
view::ViewScene record_scene(const std::string& path) {
  const Record record = read_record(path);
  std::vector<std::size_t> targets;
  for (std::size_t f = record.base.face_count();; f /= 2) {
    targets.push_back(std::max(f, record.final_faces()));
    if (f <= record.final_faces()) break;
  }
  view::ViewScene scene;
  scene.mode = view::ViewMode::Chain;
  const std::string stem = std::filesystem::path(path).stem().string();
  for (ReplayLevel& l : replay_levels(record, targets)) {
    view::ViewLevel level;
    level.name = stem + " @ " + std::to_string(l.mesh.face_count()) + " faces";
    level.error = l.max_error;
    level.mesh = std::move(l.mesh);
    scene.levels.push_back(std::move(level));
  }
  scene.title = stem;
  return scene;
}

view::ViewScene build_scene(const ViewArgs& a) {
  if (a.chain && a.compare) throw Error("--chain and --compare exclude each other");
  if (a.inputs.size() == 1 && is_record_file(a.inputs[0])) {
    if (a.compare) throw Error("--compare needs two meshes, not a record");
    view::ViewScene scene = record_scene(a.inputs[0]);
    if (!a.title.empty()) scene.title = a.title;
    return scene;
  }
  view::ViewScene scene;
  std::vector<view::ManifestLevel> entries;
  if (a.inputs.size() == 1 && view::is_manifest_path(a.inputs[0])) {
    entries = view::read_lod_manifest(a.inputs[0]);
    scene.mode = a.compare ? view::ViewMode::Compare : view::ViewMode::Chain;
  } else {
    for (const std::string& p : a.inputs) {
      if (view::is_manifest_path(p)) throw Error(p + ": an LOD manifest must be the only input");
      entries.push_back({p, 0, 0, NAN});
    }
    // Two meshes are an original and its simplification, side by side, unless --chain says they
    // are an LOD chain; more are a chain.
    scene.mode = a.compare || (entries.size() == 2 && !a.chain) ? view::ViewMode::Compare
                 : entries.size() > 1                            ? view::ViewMode::Chain
                                                                 : view::ViewMode::Single;
  }
  // Checked before loading anything: the meshes may be large.
  if (scene.mode == view::ViewMode::Compare && entries.size() != 2)
    throw Error("--compare needs exactly two meshes (original and simplified), got " +
                std::to_string(entries.size()));
  LoadOptions lo;
  lo.keep_vertex_properties = true;  // the `distance` heat map
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const view::ManifestLevel& e = entries[i];
    std::vector<std::string> warnings;
    view::ViewLevel level = view::load_view_level(e.path, lo, &warnings);
    for (const std::string& w : warnings) std::fprintf(stderr, "qem: warning: %s\n", w.c_str());
    level.error = e.error;
    if (e.faces && e.faces != level.mesh.face_count())
      throw Error(a.inputs[0] + ": level " + std::to_string(i) + " lists " + std::to_string(e.faces) +
                  " faces but " + e.path + " has " + std::to_string(level.mesh.face_count()));
    if (e.vertices && e.vertices != level.mesh.vertex_count())
      throw Error(a.inputs[0] + ": level " + std::to_string(i) + " lists " + std::to_string(e.vertices) +
                  " vertices but " + e.path + " has " + std::to_string(level.mesh.vertex_count()));
    scene.levels.push_back(std::move(level));
  }
  // Levels without a given error get the symmetric Hausdorff distance to the first (finest) level,
  // measured by surface sampling (GH97 §6.1); the first level is the reference, error 0.
  if (a.measure && scene.levels.size() > 1) {
    MeasureOptions mo;
    mo.samples = a.samples;
    for (std::size_t i = 0; i < scene.levels.size(); ++i) {
      view::ViewLevel& l = scene.levels[i];
      if (!std::isnan(l.error)) continue;
      l.error = i == 0 ? 0.0 : measure(scene.levels[0].mesh, l.mesh, mo).hausdorff;
    }
  }
  scene.title = a.title.empty() ? scene.levels[0].name : a.title;
  return scene;
}

int run_view(const ViewArgs& a) {
  view::ViewScene scene = build_scene(a);
  view::FileSet files = view::read_tree(view::find_web_assets());
  for (auto& [path, bytes] : view::scene_files(scene)) files[path] = std::move(bytes);
  if (!a.export_dir.empty()) {
    view::write_tree(a.export_dir, files);
    std::printf("qem view: wrote %zu files to %s (serve the folder over HTTP to view it)\n", files.size(),
                a.export_dir.c_str());
    return 0;
  }
  if (a.port < 0 || a.port > 65535) throw Error("--port must be 0..65535");
  view::HttpServer server(std::move(files), static_cast<std::uint16_t>(a.port));
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::printf("qem view: %zu level%s at %s (Ctrl-C to stop)\n", scene.levels.size(),
              scene.levels.size() == 1 ? "" : "s", server.url().c_str());
  std::fflush(stdout);
  server.serve(g_stop);
  return 0;
}

const bool registered = register_command(80, [](CLI::App& app) -> std::function<int()> {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* cmd =
      app.add_subcommand("view", "Show meshes in a local web page (three.js): textures, colours, glTF skins and animations; LOD "
                        "slider, side by side, seams, heat map");
  cmd->add_option("meshes", args->inputs,
                  "Mesh files (OBJ, PLY, STL, OFF, glTF), or one LOD manifest (.json) listing the levels, or "
                  "one contraction record (`qem simplify --record`): a slider over its face counts")
      ->required();
  cmd->add_flag(
      "--chain", args->chain,
      "The meshes are an LOD chain, finest first: a slider walks them (the default for three or more meshes)");
  cmd->add_flag("--compare", args->compare,
                "Two meshes (original, simplified) side by side with linked cameras and animation time (the "
                "default for two meshes)");
  cmd->add_option("--port", args->port, "Port on 127.0.0.1 to serve the page on (0 = any free port)")
      ->capture_default_str();
  cmd->add_option("--export", args->export_dir,
                  "Write the page (index.html, app.js, data/) to this folder instead of serving it");
  cmd->add_option("--title", args->title, "Page title (default: the first mesh's file name)");
  cmd->add_flag("!--no-measure", args->measure,
                "Do not measure each level's Hausdorff distance to the first level when no error is given");
  cmd->add_option("--samples", args->samples, "Surface samples for that measurement")->capture_default_str();
  return [args] { return run_view(*args); };
});

}  // namespace

}  // namespace qem::cli
