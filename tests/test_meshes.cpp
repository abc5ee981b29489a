#include "test_meshes.h"

#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "qem/error.h"
#include "qem/gltf.h"

namespace qem::test {

Mesh grid(int n) { return height_field(n, [](double, double) { return 0.0; }); }

Mesh height_field(int n, double (*f)(double, double)) {
  Mesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      double x = double(i) / n, y = double(j) / n;
      m.positions.insert(m.positions.end(), {x, y, f(x, y)});
    }
  auto id = [n](int i, int j) { return std::uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

Mesh icosphere(int level) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  Mesh m;
  m.positions = {-1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, 0, 0, -1, t, 0, 1, t,
                 0, -1, -t, 0, 1, -t, t, 0, -1, t, 0, 1, -t, 0, -1, -t, 0, 1};
  m.indices = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,
               3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
  auto normalize = [&](std::uint32_t v) {
    double* p = &m.positions[3 * v];
    double l = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    p[0] /= l, p[1] /= l, p[2] /= l;
  };
  for (std::uint32_t v = 0; v < 12; ++v) normalize(v);
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      std::uint32_t v = std::uint32_t(m.positions.size() / 3);
      for (int k = 0; k < 3; ++k) m.positions.push_back((m.positions[3 * a + k] + m.positions[3 * b + k]) / 2);
      normalize(v);
      mid[key] = v;
      return v;
    };
    std::vector<std::uint32_t> next;
    for (std::size_t f = 0; f < m.indices.size(); f += 3) {
      std::uint32_t a = m.indices[f], b = m.indices[f + 1], c = m.indices[f + 2];
      std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    m.indices = std::move(next);
  }
  return m;
}

Mesh cube() {
  Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  m.indices = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
               1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  return m;
}

Mesh tetrahedron() {
  Mesh m;
  m.positions = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
  m.indices = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};
  return m;
}

Mesh transformed(Mesh mesh, double scale, double ox, double oy, double oz) {
  const double o[3] = {ox, oy, oz};
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) mesh.positions[i] = mesh.positions[i] * scale + o[i % 3];
  return mesh;
}

Mesh concatenated(const Mesh& a, const Mesh& b) {
  Mesh m = a;
  std::uint32_t base = std::uint32_t(a.vertex_count());
  m.positions.insert(m.positions.end(), b.positions.begin(), b.positions.end());
  for (std::uint32_t i : b.indices) m.indices.push_back(i + base);
  return m;
}

std::string shared_data(const std::string& name) {
  std::filesystem::path p = std::filesystem::path(QEM_SHARED_DIR) / "data" / name;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

std::string temp_dir() {
  static std::string dir = [] {
    auto p = std::filesystem::temp_directory_path() / ("qem_tests_" + std::to_string(::getpid()));
    std::filesystem::remove_all(p);
    std::filesystem::create_directories(p);
    std::atexit([] {  // each test process removes its own folder
      std::error_code ec;
      std::filesystem::remove_all(
          std::filesystem::temp_directory_path() / ("qem_tests_" + std::to_string(::getpid())), ec);
    });
    return p.string();
  }();
  return dir;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int run_qem_quietly(const std::string& args) {
  const std::string cmd = std::string(QEM_CLI_PATH) + " " + args + " -q";
  return std::system(cmd.c_str());
}

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

// A latitude-longitude sphere whose column u = 1 repeats the positions of u = 0 with other UVs,
// and whose poles are one position with a wedge per segment.
Mesh uv_sphere(int rings, int segments) {
  Mesh m;
  VertexAttribute uv{"TEXCOORD_0", AttributeKind::TexCoord, 2, {}};
  VertexAttribute normal{"NORMAL", AttributeKind::Normal, 3, {}};
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const double theta = kPi * i / rings, phi = 2 * kPi * (j % segments) / segments;
      double p[3] = {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
      if (i == 0 || i == rings) p[0] = p[1] = 0;
      // sin(5 pi) is not exactly 0: the poles get radius 1 exactly, so each is one position.
      const double r = i == 0 || i == rings ? 1 : 1 + 0.05 * std::sin(5 * theta) * std::cos(3 * phi);
      m.positions.insert(m.positions.end(), {r * p[0], r * p[1], r * p[2]});
      uv.values.insert(uv.values.end(), {double(j) / segments, double(i) / rings});
      normal.values.insert(normal.values.end(), {p[0], p[1], p[2]});
    }
  auto id = [&](int i, int j) { return std::uint32_t(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      if (i > 0) m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j), id(i, j + 1)});
      if (i + 1 < rings) m.indices.insert(m.indices.end(), {id(i, j + 1), id(i + 1, j), id(i + 1, j + 1)});
    }
  m.attributes = {uv, normal};
  return m;
}

// A cube of side 2 whose six sides are n x n grids, each its own UV chart (a cell of a 3 x 2
// atlas) with its own vertices, so that every cube edge is a UV seam. `relief` bulges each side
// (zero on the cube's edges, so the sides still meet); normals are the side's (flat shading) or
// the position's direction.
// With `block` > 0, each side is cut further into block x block-cell charts (many small UV
// islands), and the sides of +x, +y, +z have material 0, the others material 1.
Mesh uv_cube(int n, double relief, bool flat_normals, int block) {
  Mesh m;
  VertexAttribute uv{"TEXCOORD_0", AttributeKind::TexCoord, 2, {}};
  VertexAttribute normal{"NORMAL", AttributeKind::Normal, 3, {}};
  std::map<std::array<int, 5>, std::uint32_t> ids;  // (side, i, j, chart i, chart j)
  for (int side = 0; side < 6; ++side) {
    const int axis = side / 2;
    const double sign = side % 2 ? -1 : 1;
    const auto vertex = [&](int i, int j, int ci, int cj) {
      auto [it, fresh] = ids.try_emplace({side, i, j, ci, cj}, std::uint32_t(m.vertex_count()));
      if (!fresh) return it->second;
      const double s = -1 + 2.0 * i / n, t = -1 + 2.0 * j / n;
      double p[3];
      p[axis] = sign * (1 + relief * (1 - s * s) * (1 - t * t) * std::cos(2 * s + t));
      p[(axis + 1) % 3] = sign * s;  // the side's orientation follows its outward normal
      p[(axis + 2) % 3] = t;
      m.positions.insert(m.positions.end(), {p[0], p[1], p[2]});
      // Each chart shifted in the atlas, so that neighbouring charts' UVs differ.
      uv.values.insert(uv.values.end(), {(side % 3 + 0.05 + 0.9 * (s + 1) / 2) / 3 + 0.01 * ci,
                                         (side / 3 + 0.05 + 0.9 * (t + 1) / 2) / 2 + 0.01 * cj});
      double nn[3] = {0, 0, 0};
      nn[axis] = sign;
      const double len = std::hypot(p[0], p[1], p[2]);
      if (flat_normals)
        normal.values.insert(normal.values.end(), {nn[0], nn[1], nn[2]});
      else
        normal.values.insert(normal.values.end(), {p[0] / len, p[1] / len, p[2] / len});
      return it->second;
    };
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const int ci = block > 0 ? i / block : 0, cj = block > 0 ? j / block : 0;
        const std::uint32_t a = vertex(i, j, ci, cj), b = vertex(i + 1, j, ci, cj),
                            c = vertex(i + 1, j + 1, ci, cj), d = vertex(i, j + 1, ci, cj);
        m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
        if (block > 0) m.face_materials.insert(m.face_materials.end(), 2, std::uint32_t(side % 2));
      }
  }
  m.attributes = {uv, normal};
  return m;
}

// A wavy n x n grid over the unit square whose cell (i, j) lies in UV chart chart(i, j) (two
// numbers): every chart has its own vertices and UVs (shifted in the atlas by its numbers, so
// neighbouring charts' UVs differ), so chart boundaries are seams and the points where k charts
// meet hold k wedges.
Mesh chart_grid(int n, const std::function<std::pair<int, int>(int, int)>& chart) {
  Mesh m;
  VertexAttribute uv{"TEXCOORD_0", AttributeKind::TexCoord, 2, {}};
  std::map<std::array<int, 4>, std::uint32_t> ids;  // (i, j, chart)
  auto vertex = [&](int i, int j, std::pair<int, int> c) {
    auto [it, fresh] = ids.try_emplace({i, j, c.first, c.second}, std::uint32_t(m.vertex_count()));
    if (fresh) {
      const double x = double(i) / n, y = double(j) / n;
      m.positions.insert(m.positions.end(), {x, y, 0.08 * std::sin(5 * x) * std::cos(4 * y)});
      uv.values.insert(uv.values.end(), {0.9 * x + 0.05 * c.first, 0.9 * y + 0.03 * c.second});
    }
    return it->second;
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const std::pair<int, int> c = chart(i, j);
      const std::uint32_t a = vertex(i, j, c), b = vertex(i + 1, j, c), d = vertex(i + 1, j + 1, c),
                          e = vertex(i, j + 1, c);
      m.indices.insert(m.indices.end(), {a, b, d, a, d, e});
    }
  m.attributes = {uv};
  return m;
}

// Cut into `block` x `block` cell charts.
Mesh chart_grid(int n, int block) {
  return chart_grid(n, [block](int i, int j) { return std::pair{i / block, j / block}; });
}

// Edges used by one face once the vertices are welded by position: holes and cracks. With
// `square`, those on the unit square's outline (a flat grid's own border) are not counted.
std::size_t open_edges_welded(const Mesh& m, bool square) {
  std::map<std::array<double, 3>, std::uint32_t> id;
  std::vector<std::uint32_t> welded(m.vertex_count());
  for (std::size_t v = 0; v < m.vertex_count(); ++v)
    welded[v] = id.try_emplace({m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]},
                               std::uint32_t(id.size()))
                    .first->second;
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (std::size_t f = 0; f < m.face_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      std::uint32_t a = welded[m.indices[3 * f + k]], b = welded[m.indices[3 * f + (k + 1) % 3]];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  std::vector<std::array<double, 3>> at(id.size());
  for (const auto& [p, i] : id) at[i] = p;
  auto on_outline = [&](std::uint32_t a, std::uint32_t b) {
    for (int k = 0; k < 2; ++k)
      for (double side : {0.0, 1.0})  // GH97 §6's border planes are a penalty: corners may drift a little
        if (std::abs(at[a][k] - side) < 1e-9 && std::abs(at[b][k] - side) < 1e-9) return true;
    return false;
  };
  std::size_t open = 0;
  for (const auto& [edge, n] : uses) open += n == 1 && !(square && on_outline(edge.first, edge.second));
  return open;
}

const VertexAttribute& attribute(const Mesh& m, AttributeKind kind) {
  const VertexAttribute* a = m.find_attribute(kind);
  EXPECT_NE(a, nullptr);
  return *a;
}

std::string base64(const std::string& in) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8 | (unsigned char)in[i + 2];
    for (int s = 18; s >= 0; s -= 6) out += k[(v >> s) & 63];
  }
  if (i + 1 == in.size()) {
    unsigned v = (unsigned char)in[i] << 16;
    out += {k[(v >> 18) & 63], k[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == in.size()) {
    unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8;
    out += {k[(v >> 18) & 63], k[(v >> 12) & 63], k[(v >> 6) & 63], '='};
  }
  return out;
}

std::string gltf_error(const std::string& bytes, const std::string& name) {
  try {
    GltfDocument::parse(bytes, name);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

std::string draco_bitstream(const Mesh& m, int position_bits) {
  const qem::VertexAttribute* uv = nullptr;
  const qem::VertexAttribute* normal = nullptr;
  for (const VertexAttribute& a : m.attributes) {
    if (a.kind == AttributeKind::TexCoord && !uv) uv = &a;
    if (a.kind == AttributeKind::Normal && !normal) normal = &a;
  }
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(static_cast<int>(m.face_count()));
  const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int tex = uv ? builder.AddAttribute(draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32) : -1;
  const int nor = normal ? builder.AddAttribute(draco::GeometryAttribute::NORMAL, 3, draco::DT_FLOAT32) : -1;
  std::vector<float> p(m.positions.begin(), m.positions.end()), t, n;
  if (uv) t.assign(uv->values.begin(), uv->values.end());
  if (normal) n.assign(normal->values.begin(), normal->values.end());
  for (std::size_t f = 0; f < m.face_count(); ++f) {
    const std::uint32_t* c = &m.indices[3 * f];
    const draco::FaceIndex face(static_cast<std::uint32_t>(f));
    builder.SetAttributeValuesForFace(pos, face, &p[3 * c[0]], &p[3 * c[1]], &p[3 * c[2]]);
    if (uv) builder.SetAttributeValuesForFace(tex, face, &t[2 * c[0]], &t[2 * c[1]], &t[2 * c[2]]);
    if (normal) builder.SetAttributeValuesForFace(nor, face, &n[3 * c[0]], &n[3 * c[1]], &n[3 * c[2]]);
  }
  std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  if (!mesh) throw std::runtime_error("draco_bitstream: the builder failed");
  draco::Encoder encoder;  // without quantization, the values come back exactly
  if (position_bits > 0) encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, position_bits);
  draco::EncoderBuffer stream;
  if (!encoder.EncodeMeshToBuffer(*mesh, &stream).ok())
    throw std::runtime_error("draco_bitstream: encoding failed");
  return std::string(stream.data(), stream.size());
}

nlohmann::json draco_document(const Mesh& m, std::string& bin) {
  bin = draco_bitstream(m);
  std::vector<float> p(m.positions.begin(), m.positions.end());
  std::array<float, 3> lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  for (std::size_t v = 0; v < m.vertex_count(); ++v)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[3 * v + k]), hi[k] = std::max(hi[k], p[3 * v + k]);
  nlohmann::json doc = {
      {"asset", {{"version", "2.0"}}},
      {"extensionsUsed", {"KHR_draco_mesh_compression"}},
      {"extensionsRequired", {"KHR_draco_mesh_compression"}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"meshes",
       {{{"primitives",
          {{{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}, {"NORMAL", 2}}},
            {"indices", 3},
            {"extensions",
             {{"KHR_draco_mesh_compression",
               {{"bufferView", 0},
                {"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}, {"NORMAL", 2}}}}}}}}}}}}},
      {"accessors",
       {{{"componentType", 5126}, {"count", m.vertex_count()}, {"type", "VEC3"}, {"min", lo}, {"max", hi}},
        {{"componentType", 5126}, {"count", m.vertex_count()}, {"type", "VEC2"}},
        {{"componentType", 5126}, {"count", m.vertex_count()}, {"type", "VEC3"}},
        {{"componentType", 5123}, {"count", m.indices.size()}, {"type", "SCALAR"}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", bin.size()}}}},
      {"buffers", {{{"byteLength", 0}}}}};
  return doc;
}

std::string gltf_text(nlohmann::json doc, const std::string& bin) {
  doc["buffers"][0]["byteLength"] = bin.size();
  doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(bin);
  return doc.dump();
}

namespace {

// Removes `key` from `o` when it holds `value`.
void erase_default(nlohmann::json& o, const char* key, const nlohmann::json& value) {
  if (o.is_object() && o.contains(key) && o[key] == value) o.erase(key);
}

}  // namespace

void erase_gltf_defaults(nlohmann::json& j) {
  for (nlohmann::json& a : j["accessors"]) erase_default(a, "normalized", false);
  for (nlohmann::json& mesh : j["meshes"])
    for (nlohmann::json& p : mesh["primitives"]) erase_default(p, "mode", 4);
  for (nlohmann::json& m : j["materials"]) {
    erase_default(m, "emissiveFactor", nlohmann::json::array({0.0, 0.0, 0.0}));
    erase_default(m, "alphaMode", "OPAQUE");
    erase_default(m, "alphaCutoff", 0.5);
    erase_default(m, "doubleSided", false);
    for (const char* t : {"normalTexture", "occlusionTexture", "emissiveTexture"})
      if (m.contains(t))
        erase_default(m[t], "texCoord", 0), erase_default(m[t], "scale", 1),
            erase_default(m[t], "strength", 1);
    if (m.contains("pbrMetallicRoughness")) {
      nlohmann::json& pbr = m["pbrMetallicRoughness"];
      erase_default(pbr, "baseColorFactor", nlohmann::json::array({1.0, 1.0, 1.0, 1.0}));
      erase_default(pbr, "metallicFactor", 1.0);
      erase_default(pbr, "roughnessFactor", 1.0);
      for (const char* t : {"baseColorTexture", "metallicRoughnessTexture"})
        if (pbr.contains(t)) erase_default(pbr[t], "texCoord", 0);
      if (pbr.empty()) m.erase("pbrMetallicRoughness");
    }
  }
  if (j.contains("materials") && j["materials"].empty()) j.erase("materials");
}

}  // namespace qem::test
