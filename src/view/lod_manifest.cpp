// Reads the LOD manifest (see lod_manifest.h) with nlohmann/json.
#include "view/lod_manifest.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "qem/error.h"

namespace qem::view {

bool is_manifest_path(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".json";
}

namespace {

using nlohmann::json;

// The document, or qem::Error naming the file, line and column in front, as compilers do.
json parse_document(const std::string& text, const std::string& path) {
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    // e.byte counts from 1 and is the last character read: the end of the token that did not fit.
    const std::size_t at = std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    const std::size_t line_start = at == 0 ? 0 : text.rfind('\n', at - 1) + 1;  // npos + 1 == 0
    const auto line =
        1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(line_start), '\n');
    // nlohmann says "[json.exception.parse_error.101] parse error at line L, column C: <what>".
    std::string what = e.what();
    if (std::size_t colon = what.find(": "); colon != std::string::npos) what.erase(0, colon + 2);
    throw Error(path + ":" + std::to_string(line) + ":" + std::to_string(at - line_start + 1) +
                ": invalid JSON: " + what);
  }
}

// The member `key` of an object, or nullptr (also when `v` is not an object).
const json* member(const json& v, const char* key) {
  auto it = v.find(key);
  return it == v.end() ? nullptr : &*it;
}

std::size_t count_field(const json& level, const char* key, const std::string& where) {
  const json* v = member(level, key);
  if (!v || v->is_null()) return 0;
  const double x = v->is_number() ? v->get<double>() : -1;
  if (x < 0 || x != std::floor(x) || x > 4e18)
    throw Error(where + ": \"" + key + "\" must be a non-negative integer");
  return static_cast<std::size_t>(x);
}

}  // namespace

std::vector<ManifestLevel> parse_lod_manifest(const std::string& text, const std::string& path) {
  const json doc = parse_document(text, path);
  const json* levels = doc.is_array() ? &doc : member(doc, "levels");
  if (!levels || !levels->is_array())
    throw Error(path + ": an LOD manifest is a JSON array of levels or an object with a \"levels\" array");
  if (levels->empty()) throw Error(path + ": the manifest lists no levels");
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::vector<ManifestLevel> out;
  for (std::size_t i = 0; i < levels->size(); ++i) {
    const json& level = (*levels)[i];
    std::string where = path + ": level " + std::to_string(i);
    ManifestLevel ml;
    const json* file = nullptr;
    if (level.is_string()) {
      file = &level;
    } else if (level.is_object()) {
      for (const char* key : {"path", "file", "mesh"})
        if (!file) file = member(level, key);
      ml.faces = count_field(level, "faces", where);
      ml.vertices = count_field(level, "vertices", where);
      if (const json* e = member(level, "error"); e && !e->is_null()) {
        if (!e->is_number() || e->get<double>() < 0)
          throw Error(where + ": \"error\" must be a non-negative number");
        ml.error = e->get<double>();
      }
    } else {
      throw Error(where + ": expected an object or a path string");
    }
    if (!file || !file->is_string() || file->get_ref<const std::string&>().empty())
      throw Error(where + ": missing the mesh file (\"path\")");
    std::filesystem::path p(file->get<std::string>());
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
