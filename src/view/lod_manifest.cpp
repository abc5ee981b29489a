// Reads the LOD manifest (see lod_manifest.h) with the viewer's small JSON parser.
#include "view/lod_manifest.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "qem/error.h"
#include "view/json.h"

namespace qem::view {

bool is_manifest_path(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".json";
}

namespace {

std::size_t count_field(const JsonValue& level, const char* key, const std::string& where) {
  const JsonValue* v = level.find(key);
  if (!v || v->is_null()) return 0;
  if (!v->is_number() || v->number < 0 || v->number != std::floor(v->number) || v->number > 4e18)
    throw Error(where + ": \"" + key + "\" must be a non-negative integer");
  return static_cast<std::size_t>(v->number);
}

}  // namespace

std::vector<ManifestLevel> parse_lod_manifest(const std::string& text, const std::string& path) {
  JsonValue doc = parse_json(text, path);
  const JsonValue* levels = doc.is_array() ? &doc : doc.find("levels");
  if (!levels || !levels->is_array())
    throw Error(path + ": an LOD manifest is a JSON array of levels or an object with a \"levels\" array");
  if (levels->array.empty()) throw Error(path + ": the manifest lists no levels");
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::vector<ManifestLevel> out;
  for (std::size_t i = 0; i < levels->array.size(); ++i) {
    const JsonValue& level = levels->array[i];
    std::string where = path + ": level " + std::to_string(i);
    ManifestLevel ml;
    const JsonValue* file = nullptr;
    if (level.is_string()) {
      file = &level;
    } else if (level.is_object()) {
      for (const char* key : {"path", "file", "mesh"})
        if (!file) file = level.find(key);
      ml.faces = count_field(level, "faces", where);
      ml.vertices = count_field(level, "vertices", where);
      if (const JsonValue* e = level.find("error"); e && !e->is_null()) {
        if (!e->is_number() || e->number < 0)
          throw Error(where + ": \"error\" must be a non-negative number");
        ml.error = e->number;
      }
    } else {
      throw Error(where + ": expected an object or a path string");
    }
    if (!file || !file->is_string() || file->string.empty())
      throw Error(where + ": missing the mesh file (\"path\")");
    std::filesystem::path p(file->string);
    ml.path = p.is_absolute() ? p.string() : (dir / p).lexically_normal().string();
    out.push_back(std::move(ml));
  }
  return out;
}

std::vector<ManifestLevel> read_lod_manifest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open the LOD manifest");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_lod_manifest(ss.str(), path);
}

}  // namespace qem::view
