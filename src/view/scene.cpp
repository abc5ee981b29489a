// Serialises a ViewScene into the files the page fetches (see scene.h and docs/viewer.md).
#include "view/scene.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "geometry/box.h"
#include "geometry/vec3.h"
#include "qem/error.h"

namespace qem::view {

const char* to_string(ViewMode mode) {
  switch (mode) {
    case ViewMode::Single:
      return "single";
    case ViewMode::Chain:
      return "chain";
    case ViewMode::Compare:
      return "compare";
  }
  return "single";
}

namespace {

// Little endian whatever the host, so the bytes (and the page's typed arrays) never depend on it.
void put_u32(std::string& out, std::uint32_t v) {
  char b[4] = {static_cast<char>(v & 0xFF), static_cast<char>((v >> 8) & 0xFF),
               static_cast<char>((v >> 16) & 0xFF), static_cast<char>((v >> 24) & 0xFF)};
  out.append(b, 4);
}
void put_f32(std::string& out, double v) {
  put_u32(out, std::bit_cast<std::uint32_t>(static_cast<float>(v)));
}

}  // namespace

std::map<std::string, std::string> scene_files(const ViewScene& scene) {
  if (scene.levels.empty()) throw Error("no mesh to show");
  if (scene.mode == ViewMode::Compare && scene.levels.size() != 2)
    throw Error("--compare needs exactly two meshes (original and simplified), got " +
                std::to_string(scene.levels.size()));

  // One frame for all levels: the page centres and zooms once, so switching levels never jumps.
  BoxOfPoints all;
  double dlo = INFINITY, dhi = -INFINITY;
  for (const ViewLevel& level : scene.levels) {
    const Mesh& m = level.mesh;
    all.add_all(m.positions);
    for (std::uint32_t idx : m.indices)
      if (idx >= m.vertex_count())
        throw Error(level.name + ": face index " + std::to_string(idx) + " out of range (" +
                    std::to_string(m.vertex_count()) + " vertices)");
    if (const VertexProperty* d = m.find_property(kHeatProperty))
      for (double x : d->values)
        if (std::isfinite(x)) dlo = std::min(dlo, x), dhi = std::max(dhi, x);
  }
  // The bounding sphere of the box (no vertex, or one point: centre 0 or that point, radius 1).
  const Box box = all.box();
  const Vec3 center = box_center(box);
  const double radius = box.diagonal() > 0 ? 0.5 * box.diagonal() : 1;

  // Keys in the order docs/viewer.md lists them, for whoever reads the file.
  using json = nlohmann::ordered_json;
  json doc = {{"format", "qem-view"},
              {"version", 2},
              {"mode", to_string(scene.mode)},
              {"title", scene.title},
              {"center", {center[0], center[1], center[2]}},
              {"radius", radius},
              {"distance_range", dlo <= dhi ? json{dlo, dhi} : json()},
              {"levels", json::array()}};
  std::map<std::string, std::string> files;
  for (std::size_t li = 0; li < scene.levels.size(); ++li) {
    const ViewLevel& level = scene.levels[li];
    const Mesh& m = level.mesh;
    const std::string base = "data/level" + std::to_string(li), dir = base + "/";
    // An unknown error (NaN) is written as null.
    json entry = {{"name", level.name}, {"faces", m.face_count()}, {"vertices", m.vertex_count()}, {"error", level.error}};
    for (const auto& [key, bytes] : level.files) {
      // Keys become paths of `--export`: never absolute, never out of the level's folder.
      const std::filesystem::path k(key);
      if (key.empty() || k.is_absolute() || k.lexically_normal().generic_string() != key || *k.begin() == "..")
        throw Error(level.name + ": file key '" + key + "' is not a plain relative path");
      files[dir + key] = bytes;
    }
    if (!level.gltf.empty()) {
      if (!level.files.count(level.gltf)) throw Error(level.name + ": the glTF document is not among its files");
      entry["gltf"] = dir + level.gltf;
      doc["levels"].push_back(std::move(entry));
      continue;
    }
    entry["positions"] = base + ".pos.f32";
    entry["indices"] = base + ".idx.u32";
    std::string pos, idx;
    pos.reserve(m.positions.size() * 4);
    for (std::size_t i = 0; i < m.positions.size(); ++i) put_f32(pos, m.positions[i] - center[int(i % 3)]);
    idx.reserve(m.indices.size() * 4);
    for (std::uint32_t v : m.indices) put_u32(idx, v);
    files[base + ".pos.f32"] = std::move(pos);
    files[base + ".idx.u32"] = std::move(idx);
    const VertexProperty* d = m.find_property(kHeatProperty);
    if (d && d->values.size() == m.vertex_count()) {
      std::string dist;
      dist.reserve(d->values.size() * 4);
      for (double x : d->values) put_f32(dist, std::isfinite(x) ? x : 0.0);
      files[base + ".dist.f32"] = std::move(dist);
      entry["distance"] = base + ".dist.f32";
    }
    // The first normals, texture coordinates and colours: what a renderer draws with.
    auto attribute = [&](AttributeKind kind, const char* field, const char* suffix, std::uint32_t take) {
      const VertexAttribute* a = m.find_attribute(kind);
      if (!a) return;
      if (a->components == 0 || a->components > 4 || a->values.size() != a->components * m.vertex_count())
        throw Error(level.name + ": attribute " + a->name + " has " + std::to_string(a->values.size()) +
                    " values for " + std::to_string(m.vertex_count()) + " vertices of " +
                    std::to_string(a->components) + " components");
      if (a->components < take) return;  // e.g. a one-component "texture coordinate"
      if (take == 0) take = a->components;
      std::string out;
      out.reserve(m.vertex_count() * take * 4);
      for (std::size_t v = 0; v < m.vertex_count(); ++v)
        for (std::uint32_t c = 0; c < take; ++c) {
          const double x = a->values[v * a->components + c];
          put_f32(out, std::isfinite(x) ? x : 0.0);
        }
      const std::string path = base + suffix;
      files[path] = std::move(out);
      entry[field] = path;
      if (kind == AttributeKind::Color) entry["color_components"] = take;
    };
    attribute(AttributeKind::Normal, "normals", ".nrm.f32", 3);
    attribute(AttributeKind::TexCoord, "uvs", ".uv.f32", 2);
    attribute(AttributeKind::Color, "colors", ".col.f32", 0);
    if (!level.materials.empty()) {
      if (!m.face_materials.empty() && m.face_materials.size() != m.face_count())
        throw Error(level.name + ": " + std::to_string(m.face_materials.size()) + " face materials for " +
                    std::to_string(m.face_count()) + " faces");
      std::string mats;
      mats.reserve(m.face_count() * 4);
      for (std::size_t f = 0; f < m.face_count(); ++f) {
        const std::uint32_t id = m.face_materials.empty() ? 0 : m.face_materials[f];
        if (id >= level.materials.size())
          throw Error(level.name + ": face " + std::to_string(f) + " has material " + std::to_string(id) + " of " +
                      std::to_string(level.materials.size()));
        put_u32(mats, id);
      }
      files[base + ".mat.u32"] = std::move(mats);
      entry["face_materials"] = base + ".mat.u32";
      json list = json::array();
      for (const ViewMaterial& mat : level.materials) {
        if (!mat.texture.empty() && !level.files.count(mat.texture))
          throw Error(level.name + ": material " + mat.name + ": texture " + mat.texture + " is not among its files");
        list.push_back({{"name", mat.name},
                        {"color", {mat.color[0], mat.color[1], mat.color[2]}},
                        {"opacity", mat.opacity},
                        {"texture", mat.texture.empty() ? json() : json(dir + mat.texture)}});
      }
      entry["materials"] = std::move(list);
    }
    doc["levels"].push_back(std::move(entry));
  }
  // Names and titles come from file names, which need not be UTF-8: such bytes become U+FFFD
  // rather than an exception (JSON text must be UTF-8).
  files["data/scene.json"] = doc.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
  return files;
}

}  // namespace qem::view
