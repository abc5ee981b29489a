// Serialises a ViewScene into the files the page fetches (see scene.h and docs/viewer.md).
#include "view/scene.h"

#include <algorithm>
#include <bit>
#include <cstdint>

#include "geometry/box.h"
#include "geometry/vec3.h"
#include "qem/error.h"
#include "view/json.h"

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

  std::map<std::string, std::string> files;
  std::string json = "{\n  \"format\": \"qem-view\",\n  \"version\": 1,\n";
  json += "  \"mode\": " + json_quote(to_string(scene.mode)) + ",\n";
  json += "  \"title\": " + json_quote(scene.title) + ",\n";
  json += "  \"center\": [" + json_number(center[0]) + ", " + json_number(center[1]) + ", " +
          json_number(center[2]) + "],\n";
  json += "  \"radius\": " + json_number(radius) + ",\n";
  json += "  \"distance_range\": " +
          (dlo <= dhi ? "[" + json_number(dlo) + ", " + json_number(dhi) + "]" : std::string("null")) + ",\n";
  json += "  \"levels\": [";
  for (std::size_t li = 0; li < scene.levels.size(); ++li) {
    const ViewLevel& level = scene.levels[li];
    const Mesh& m = level.mesh;
    std::string base = "data/level" + std::to_string(li);
    std::string pos, idx, dist;
    pos.reserve(m.positions.size() * 4);
    for (std::size_t i = 0; i < m.positions.size(); ++i) put_f32(pos, m.positions[i] - center[int(i % 3)]);
    idx.reserve(m.indices.size() * 4);
    for (std::uint32_t v : m.indices) put_u32(idx, v);
    files[base + ".pos.f32"] = std::move(pos);
    files[base + ".idx.u32"] = std::move(idx);
    json += li ? ",\n    {" : "\n    {";
    json += "\"name\": " + json_quote(level.name);
    json += ", \"faces\": " + std::to_string(m.face_count());
    json += ", \"vertices\": " + std::to_string(m.vertex_count());
    json += ", \"error\": " + json_number(level.error);
    json += ", \"positions\": " + json_quote(base + ".pos.f32");
    json += ", \"indices\": " + json_quote(base + ".idx.u32");
    const VertexProperty* d = m.find_property(kHeatProperty);
    if (d && d->values.size() == m.vertex_count()) {
      dist.reserve(d->values.size() * 4);
      for (double x : d->values) put_f32(dist, std::isfinite(x) ? x : 0.0);
      files[base + ".dist.f32"] = std::move(dist);
      json += ", \"distance\": " + json_quote(base + ".dist.f32");
    }
    json += "}";
  }
  json += "\n  ]\n}\n";
  files["data/scene.json"] = std::move(json);
  return files;
}

}  // namespace qem::view
