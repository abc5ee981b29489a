// Models with their materials, textures and glTF documents for the viewer (model_assets.h).
#include "view/model_assets.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "io/gltf_prepass.h"
#include "qem/error.h"
#include "qem/gltf.h"
#include "view/mtl.h"
#include "view/safe_path.h"

namespace fs = std::filesystem;

namespace qem::view {

namespace {

std::string read_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  if (!in) throw Error(file.string() + ": cannot read");
  return ss.str();
}

// Adds the file `ref` (relative to `from`, which must lie in `folder`) to the level's files;
// returns its key, or "" with a warning when it cannot be served.
std::string add_reference(ViewLevel& level, const fs::path& folder, const fs::path& from,
                          const std::string& ref, const std::string& model, const char* what,
                          std::vector<std::string>* warnings) {
  // Resolved against `from`, then expressed relative to the model's folder.
  std::string rel = (from / fs::path(ref)).generic_string();
  std::string why;
  auto found = resolve_inside(folder, rel, &why);
  if (!found) {
    if (warnings) warnings->push_back(model + ": " + what + " '" + ref + "' not shown: " + why);
    return "";
  }
  if (!level.files.count(found->key)) level.files[found->key] = read_file(found->file);
  return found->key;
}

void add_obj_materials(ViewLevel& level, const fs::path& folder, const std::string& model,
                       std::vector<std::string>* warnings) {
  const Mesh& m = level.mesh;
  // No library, or no face names a material: nothing to draw but the default look.
  if (m.material_library.empty() || m.material_names.empty()) return;
  std::string why;
  auto found = resolve_inside(folder, m.material_library, &why);
  // `mtllib a.mtl b.mtl` names several libraries: the first one that exists is read.
  for (std::istringstream names(m.material_library); !found && names;) {
    std::string one;
    if (names >> one) found = resolve_inside(folder, one, nullptr);
  }
  if (!found) {
    // Without its library a material is only a name: the page's default look says more.
    if (warnings)
      warnings->push_back(model + ": material library '" + m.material_library + "' not shown: " + why);
    return;
  }
  const std::vector<MtlMaterial> library =
      parse_mtl(read_file(found->file), found->file.filename().string(), warnings);
  const fs::path library_dir = fs::path(found->key).parent_path();
  if (library.empty()) return;
  std::map<std::string, const MtlMaterial*> by_name;
  for (const MtlMaterial& mm : library) by_name.emplace(mm.name, &mm);
  for (const std::string& name : m.material_names) {
    ViewMaterial vm;
    vm.name = name;
    auto it = by_name.find(vm.name);
    if (it != by_name.end()) {
      const MtlMaterial& mm = *it->second;
      for (int k = 0; k < 3; ++k) vm.color[k] = mm.diffuse[k];
      vm.opacity = mm.opacity;
      if (!mm.diffuse_map.empty())
        vm.texture = add_reference(level, folder, library_dir, mm.diffuse_map, model, "texture", warnings);
    } else {
      for (double& c : vm.color) c = MtlMaterial{}.diffuse[0];  // the MTL default grey
      if (warnings && !vm.name.empty())
        warnings->push_back(model + ": material '" + vm.name + "' is not in its library; shown plain");
    }
    level.materials.push_back(std::move(vm));
  }
}

// PLY face colours, which the reader keeps as materials named "rgb(R,G,B)" (bytes): drawn as
// their colours. Nothing when any material is named otherwise.
void add_face_colours(ViewLevel& level) {
  std::vector<ViewMaterial> out;
  for (const std::string& name : level.mesh.material_names) {
    unsigned rgb[3];
    int used = 0;
    if (std::sscanf(name.c_str(), "rgb(%u,%u,%u)%n", &rgb[0], &rgb[1], &rgb[2], &used) != 3 ||
        static_cast<std::size_t>(used) != name.size() || rgb[0] > 255 || rgb[1] > 255 || rgb[2] > 255)
      return;
    ViewMaterial vm;
    vm.name = name;
    for (int k = 0; k < 3; ++k) vm.color[k] = rgb[k] / 255.0;
    out.push_back(std::move(vm));
  }
  level.materials = std::move(out);
}

// A glTF document's JSON: the whole text, or a .glb's JSON chunk.
std::string_view json_text_of(const std::string& bytes, const std::string& name) {
  const std::optional<std::string_view> json = io::gltf::json_of(bytes);
  if (!json) throw Error(name + ": not a valid GLB (no JSON chunk)");
  return *json;
}

}  // namespace

std::vector<std::string> gltf_external_uris(const std::string& bytes, const std::string& name) {
  nlohmann::json doc = nlohmann::json::parse(json_text_of(bytes, name), nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) throw Error(name + ": the glTF JSON cannot be parsed");
  std::vector<std::string> out;
  for (const char* list : {"buffers", "images"}) {
    auto it = doc.find(list);
    if (it == doc.end() || !it->is_array()) continue;
    for (const auto& item : *it) {
      if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
      const std::string uri = item["uri"].get<std::string>();
      if (uri.rfind("data:", 0) != 0) out.push_back(uri);
    }
  }
  return out;
}

ViewLevel load_view_level(const std::string& path, const LoadOptions& options,
                          std::vector<std::string>* warnings) {
  ViewLevel level;
  const fs::path file(path);
  const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
  level.name = file.filename().string();
  LoadReport report;
  level.mesh = load_mesh(path, options, &report);
  if (warnings) warnings->insert(warnings->end(), report.warnings.begin(), report.warnings.end());
  if (report.format == FileFormat::Gltf) {
    // The document itself goes to the page; the mesh still gives counts, frame and error.
    level.gltf = level.name;
    level.files[level.gltf] = read_file(file);
    // three.js's GLTFLoader reads compressed geometry only with decoders that the page does not
    // carry: such a document goes to the page decoded (GltfDocument writes it uncompressed, its
    // external buffers embedded).
    const std::string_view json = json_text_of(level.files[level.gltf], path);
    if (io::gltf::names_compression(json))
      level.files[level.gltf] = GltfDocument::load(path).serialize(io::gltf::is_glb(level.files[level.gltf]));
    for (const std::string& uri : gltf_external_uris(level.files[level.gltf], path))
      add_reference(level, folder, fs::path(), percent_decode(uri), path, "glTF resource", warnings);
  } else if (report.format == FileFormat::Obj && options.read_attributes) {
    add_obj_materials(level, folder, path, warnings);
  } else if (report.format == FileFormat::Ply && options.read_attributes) {
    add_face_colours(level);
  }
  return level;
}

}  // namespace qem::view
