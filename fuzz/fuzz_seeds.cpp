// fuzz_seeds OUTDIR: writes the seed corpora and dictionaries the fuzzers start from, all made in
// code (no copied files): small meshes serialised by qem's own writers in every format and variant,
// plus hand-written files that use the format features the writers never emit (polygons, comments,
// negative OBJ indices, PLY extra properties, big-endian data and header lines without a keyword,
// COFF colours...).
//
//   OUTDIR/{obj,ply,stl,off,gltf,simplify}/seed_*   one file per seed
//   OUTDIR/{obj,ply,stl,off,gltf}.dict              libFuzzer dictionaries (-dict=)
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <meshoptimizer.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "fuzz_checks.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/mesh.h"

namespace {

namespace fs = std::filesystem;

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  if (!out) {
    std::fprintf(stderr, "fuzz_seeds: cannot write %s\n", path.string().c_str());
    std::exit(1);
  }
}

qem::Mesh tetrahedron() {
  qem::Mesh m;
  m.positions = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
  m.indices = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};
  return m;
}

qem::Mesh cube() {
  qem::Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  m.indices = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
               1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  return m;
}

/// A wavy n x n grid with one scalar property per vertex (for the PLY property paths).
qem::Mesh grid(int n) {
  qem::Mesh m;
  qem::VertexProperty k{"quality", {}};
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      double x = double(i) / n, y = double(j) / n;
      m.positions.insert(m.positions.end(), {x, y, 0.1 * std::sin(6 * x) * std::cos(5 * y)});
      k.values.push_back(x - y);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      std::uint32_t a = std::uint32_t(j * (n + 1) + i), b = a + 1, c = a + std::uint32_t(n) + 2, d = c - 1;
      m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
    }
  m.vertex_properties.push_back(std::move(k));
  return m;
}

/// One degenerate face, one unreferenced vertex, awkward coordinates.
qem::Mesh odd() {
  qem::Mesh m;
  m.positions = {0, 0, 0, 1e-300, 0, 0, 0, 1e300, 0, -0.0, 0.1, 3.25, 7, 7, 7};
  m.indices = {0, 1, 2, 0, 0, 3, 1, 2, 3};
  return m;
}

/// A tetrahedron split into 12 wedges (one per face corner, as a UV-mapped, flat-shaded mesh reads)
/// with normals, texture coordinates, RGBA colours and two materials: the attribute paths of every
/// reader and writer.
qem::Mesh attributed() {
  const qem::Mesh t = tetrahedron();
  qem::Mesh m;
  qem::VertexAttribute n{"NORMAL", qem::AttributeKind::Normal, 3, {}};
  qem::VertexAttribute uv{"TEXCOORD_0", qem::AttributeKind::TexCoord, 2, {}};
  qem::VertexAttribute c{"COLOR_0", qem::AttributeKind::Color, 4, {}};
  for (std::size_t f = 0; f < t.face_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = t.indices[3 * f + k];
      m.positions.insert(m.positions.end(), t.positions.begin() + 3 * v, t.positions.begin() + 3 * v + 3);
      m.indices.push_back(std::uint32_t(m.indices.size()));
      n.values.insert(n.values.end(), {0.0, 0.0, f % 2 ? 1.0 : -1.0});
      uv.values.insert(uv.values.end(), {k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0});
      c.values.insert(c.values.end(), {double(f) / 4, double(k) / 3, 0.5, 1.0});
    }
  m.attributes = {n, uv, c};
  m.face_materials = {0, 0, 1, 1};
  m.material_names = {"red", "blue"};
  m.material_library = "tetra.mtl";
  return m;
}

void serialised_seeds(const fs::path& out) {
  struct Named {
    const char* name;
    qem::Mesh mesh;
  };
  const std::vector<Named> meshes = {
      {"tetrahedron", tetrahedron()}, {"cube", cube()},      {"grid", grid(3)}, {"odd", odd()},
      {"attributed", attributed()},   {"empty", qem::Mesh{}}};
  struct Format {
    qem::FileFormat format;
    const char* dir;
  };
  const Format formats[] = {{qem::FileFormat::Obj, "obj"},
                            {qem::FileFormat::Ply, "ply"},
                            {qem::FileFormat::Stl, "stl"},
                            {qem::FileFormat::Off, "off"},
                            {qem::FileFormat::Gltf, "gltf"}};
  for (const Format& f : formats)
    for (const Named& m : meshes)
      for (const qem::SaveOptions& o : qem::fuzz::save_variants(f.format)) {
        std::string bytes;
        try {
          bytes = qem::serialize_mesh(m.mesh, o);
        } catch (const qem::Error&) {
          continue;  // the float writers refuse odd()'s 1e300: no such file can exist
        }
        std::string file = std::string("seed_") + m.name + (o.binary ? "_binary" : "_ascii") +
                           (o.double_precision ? "_double" : "");
        write_file(out / f.dir / file, bytes);
      }
}

/// Big-endian binary PLY with an extra property, uchar counts and a quad, built byte by byte.
std::string ply_big_endian() {
  std::string s =
      "ply\nformat binary_big_endian 1.0\ncomment made by fuzz_seeds\nelement vertex 4\n"
      "property float x\nproperty float y\nproperty float z\nproperty uchar red\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  auto be32 = [&s](std::uint32_t v) {
    for (int k = 3; k >= 0; --k) s += char((v >> (8 * k)) & 0xff);
  };
  auto f32 = [&be32](float x) {
    std::uint32_t bits;
    std::memcpy(&bits, &x, 4);
    be32(bits);
  };
  const float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (const auto& v : p) {
    for (float x : v) f32(x);
    s += char(200);
  }
  s += char(4);
  for (std::uint32_t i = 0; i < 4; ++i) be32(i);
  return s;
}

void handwritten_seeds(const fs::path& out) {
  write_file(out / "obj" / "hand_polygons",
             "# polygons, slashes, negative indices, groups, a line continuation\n"
             "mtllib x.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1 0.2 0.4 0.6\n"
             "vt 0 0\nvt 1 0\nvn 0 0 1\ng top\nusemtl red\ns off\n"
             "f 1/1/1 2/2/1 3//1 4\nf -5 -4 \\\n -1\nf 2 3 5\nl 1 2\n");
  write_file(out / "obj" / "hand_attributes",
             "# vt/vn corners, a corner without vt, 1D and 3D vt, colours, materials before and after\n"
             "mtllib a b.mtl\nv 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0\nv 0 1 0 0.5 0.5 0.5\n"
             "vt 0 0\nvt 1\nvt 1 1 0\nvn 0 0 1\nvn 0 0 -1\nf 1/1/1 2/2/1 3/3/1\nusemtl m1\n"
             "f 1/-3/-2 3/-1/-2 4\nusemtl\nf 4//2 3//2 2//2\nusemtl m1\nf 1/1 2/2 4/3 3/1\n");
  write_file(out / "obj" / "hand_crlf", "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n");
  write_file(out / "ply" / "hand_ascii_props",
             "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
             "property double z\nproperty float confidence\nproperty float intensity\n"
             "element face 2\nproperty list uchar uint vertex_indices\nproperty uchar red\n"
             "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
             "0 0 0 1 0.5\n1 0 0 1 0.5\n1 1 0 0.5 1\n0 1 0 0.25 0\n3 0 1 2 7\n4 0 1 2 3 9\n0 1\n");
  write_file(out / "ply" / "hand_big_endian", ply_big_endian());
  // Old Blender exporters: a credit line without `comment`, skipped with a warning.
  write_file(out / "ply" / "hand_blender_header",
             "ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org, source file: 'x.blend'\n"
             "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\n"
             "property float ny\nproperty float nz\nelement face 1\nproperty list uchar uint vertex_indices\n"
             "end_header\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n");
  // Attribute properties in every spelling: float colours with alpha, texture_u/v, ushort and face
  // colours.
  write_file(
      out / "ply" / "hand_attributes",
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\nproperty float texture_u\n"
      "property float texture_v\nproperty float red\nproperty float green\nproperty float blue\n"
      "property float alpha\nproperty ushort quality\nelement face 2\n"
      "property list uchar int vertex_indices\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nend_header\n0 0 0 0 0 1 0 0 1 0 0 1 7\n1 0 0 0 0 1 1 0 0 1 0 0.5 8\n"
      "1 1 0 0 0 1 1 1 0 0 1 1 9\n0 1 0 0 0 1 0 1 0.2 0.2 0.2 0 10\n3 0 1 2 255 0 0\n3 0 2 3 0 0 255\n");
  write_file(
      out / "ply" / "hand_uchar_colours",
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float s\nproperty float t\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 255 0 0 0 0\n1 0 0 0 255 0 1 0\n0 1 0 0 0 255 0 1\n3 0 1 2\n");
  write_file(
      out / "stl" / "hand_ascii",
      "solid part\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n"
      "      vertex 0 1 0\n    endloop\n  endfacet\n  facet normal 0 0 -1\n    outer loop\n"
      "      vertex 0 0 0\n      vertex 0 1 0\n      vertex 1 0 0\n    endloop\n  endfacet\nendsolid part\n");
  write_file(out / "off" / "hand_coff",
             "COFF\n# colours and a quad\n4 2 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n"
             "1 1 0 0 0 255 255\n0 1 0 9 9 9 255\n3 0 1 2\n4 0 1 2 3 1 0 0\n");
  write_file(out / "off" / "hand_oneline", "OFF 3 1 0\n0 0 0 1 0 0 0 1 0 3 0 1 2\n");
  // glTF: a cube with a normal, texture coordinates, a colour and two materials, as .gltf and .glb.
  qem::Mesh m = cube();
  qem::VertexAttribute n{"NORMAL", qem::AttributeKind::Normal, 3, {}},
      uv{"TEXCOORD_0", qem::AttributeKind::TexCoord, 2, {}}, c{"COLOR_0", qem::AttributeKind::Color, 4, {}};
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    n.values.insert(n.values.end(), {0, 0, 1});
    uv.values.insert(uv.values.end(), {m.positions[3 * v], m.positions[3 * v + 1]});
    c.values.insert(c.values.end(), {1, 0.5, 0, 1});
  }
  m.attributes = {n, uv, c};
  m.face_materials.assign(m.face_count(), 0);
  m.face_materials[0] = 1;
  m.material_names = {"a", "b"};
  write_file(out / "gltf" / "hand_attributes.gltf", qem::serialize_mesh(m, qem::FileFormat::Gltf, false));
  write_file(out / "gltf" / "hand_attributes.glb", qem::serialize_mesh(m, qem::FileFormat::Gltf, true));
}

// A .glb: `json` (padded with spaces) and `bin` as buffer 0's BIN chunk.
std::string glb(std::string json, std::string bin) {
  json.resize((json.size() + 3) & ~std::size_t(3), ' ');
  bin.resize((bin.size() + 3) & ~std::size_t(3), '\0');
  std::string out = "glTF";
  auto u32 = [&out](std::size_t v) {
    const std::uint32_t w = std::uint32_t(v);
    out.append(reinterpret_cast<const char*>(&w), 4);
  };
  u32(2), u32(28 + json.size() + bin.size()), u32(json.size()), out += "JSON", out += json;
  u32(bin.size()), out += "BIN", out += '\0', out += bin;
  return out;
}

// glTF whose geometry is compressed: a tetrahedron as a Draco bitstream, and as meshoptimizer's
// vertex and index codecs in a fallback buffer (the decoders of io/gltf_draco.h, io/gltf_meshopt.h).
void compressed_gltf_seeds(const fs::path& out) {
  const qem::Mesh t = tetrahedron();
  const std::vector<float> p(t.positions.begin(), t.positions.end());
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(int(t.face_count()));
  const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  for (std::uint32_t f = 0; f < t.face_count(); ++f)
    builder.SetAttributeValuesForFace(pos, draco::FaceIndex(f), &p[3 * t.indices[3 * f]],
                                      &p[3 * t.indices[3 * f + 1]], &p[3 * t.indices[3 * f + 2]]);
  draco::Encoder encoder;
  draco::EncoderBuffer stream;
  if (!encoder.EncodeMeshToBuffer(*builder.Finalize(), &stream).ok()) std::exit(1);
  const std::string draco_length = std::to_string(stream.size());
  write_file(
      out / "gltf" / "hand_draco.glb",
      glb(R"({"asset":{"version":"2.0"},"extensionsUsed":["KHR_draco_mesh_compression"],)"
          R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"extensions":)"
          R"({"KHR_draco_mesh_compression":{"bufferView":0,"attributes":{"POSITION":0}}}}]}],)"
          R"("accessors":[{"componentType":5126,"count":4,"type":"VEC3","min":[-1,-1,-1],"max":[1,1,1]},)"
          R"({"componentType":5123,"count":12,"type":"SCALAR"}],"bufferViews":[{"buffer":0,"byteLength":)" +
              draco_length + R"(}],"buffers":[{"byteLength":)" + draco_length + "}]}",
          std::string(stream.data(), stream.size())));

  std::string vertices(meshopt_encodeVertexBufferBound(4, 12), '\0'),
      indices(meshopt_encodeIndexBufferBound(12, 4), '\0');
  vertices.resize(meshopt_encodeVertexBuffer(reinterpret_cast<unsigned char*>(vertices.data()),
                                             vertices.size(), p.data(), 4, 12));
  indices.resize(meshopt_encodeIndexBuffer(reinterpret_cast<unsigned char*>(indices.data()), indices.size(),
                                           t.indices.data(), 12));
  const std::string vn = std::to_string(vertices.size()), in = std::to_string(indices.size());
  vertices.resize((vertices.size() + 3) & ~std::size_t(3), '\0');  // the indices' data 4-byte aligned
  const std::string at = std::to_string(vertices.size());
  write_file(
      out / "gltf" / "hand_meshopt.glb",
      glb(R"({"asset":{"version":"2.0"},"extensionsUsed":["EXT_meshopt_compression"],)"
          R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
          R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-1,-1,-1],"max":[1,1,1]},)"
          R"({"bufferView":1,"componentType":5123,"count":12,"type":"SCALAR"}],"bufferViews":[)"
          R"({"buffer":1,"byteLength":48,"byteStride":12,"extensions":{"EXT_meshopt_compression":)"
          R"({"buffer":0,"byteLength":)" +
              vn +
              R"(,"byteStride":12,"count":4,"mode":"ATTRIBUTES"}}},)"
              R"({"buffer":1,"byteOffset":48,"byteLength":24,"extensions":{"EXT_meshopt_compression":)"
              R"({"buffer":0,"byteOffset":)" +
              at + R"(,"byteLength":)" + in +
              R"(,"byteStride":2,"count":12,"mode":"TRIANGLES"}}}],"buffers":[{"byteLength":)" +
              std::to_string(vertices.size() + indices.size()) +
              R"(},{"byteLength":72,"extensions":{"EXT_meshopt_compression":{"fallback":true}}}]})",
          vertices + indices));
}

// A tetrahedron drawn twice by EXT_mesh_gpu_instancing (translations and quantized rotations).
void instanced_gltf_seed(const fs::path& out) {
  const qem::Mesh t = tetrahedron();
  std::string bin;
  for (double v : t.positions) {
    const float f = float(v);
    bin.append(reinterpret_cast<const char*>(&f), 4);
  }
  for (std::uint32_t v : t.indices) {
    const auto i = std::uint16_t(v);
    bin.append(reinterpret_cast<const char*>(&i), 2);
  }
  for (float f : {0.0f, 0.0f, 0.0f, 3.0f, 0.0f, 0.0f}) bin.append(reinterpret_cast<const char*>(&f), 4);
  for (std::int16_t q : {0, 0, 0, 32767, 0, 23170, 0, 23170})
    bin.append(reinterpret_cast<const char*>(&q), 2);
  write_file(
      out / "gltf" / "hand_instanced.glb",
      glb(R"({"asset":{"version":"2.0"},"extensionsUsed":["EXT_mesh_gpu_instancing"],)"
          R"("scenes":[{"nodes":[0]}],"nodes":[{"mesh":0,"extensions":{"EXT_mesh_gpu_instancing":)"
          R"({"attributes":{"TRANSLATION":2,"ROTATION":3}}}}],)"
          R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
          R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-1,-1,-1],"max":[1,1,1]},)"
          R"({"bufferView":1,"componentType":5123,"count":12,"type":"SCALAR"},)"
          R"({"bufferView":2,"componentType":5126,"count":2,"type":"VEC3"},)"
          R"({"bufferView":3,"componentType":5122,"normalized":true,"count":2,"type":"VEC4"}],)"
          R"("bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":24},)"
          R"({"buffer":0,"byteOffset":72,"byteLength":24},{"buffer":0,"byteOffset":96,"byteLength":16}],)"
          R"("buffers":[{"byteLength":112}]})",
          bin));
}

void simplify_seeds(const fs::path& out) {
  // The simplify fuzzer decodes any bytes into a case, so varied random bytes are valid seeds.
  std::mt19937 rng(20240601);
  const std::size_t sizes[] = {16, 64, 200, 400, 700, 1000, 1500, 2000};
  int n = 0;
  for (std::size_t size : sizes)
    for (int rep = 0; rep < 3; ++rep) {
      std::string bytes(size, '\0');
      for (char& c : bytes) c = char(rng() & 0xff);
      write_file(out / "simplify" / ("seed_random_" + std::to_string(n++)), bytes);
    }
}

void dictionaries(const fs::path& out) {
  auto dict = [&out](const char* name, const std::vector<std::string>& words) {
    std::string s;
    for (std::size_t i = 0; i < words.size(); ++i) s += "kw" + std::to_string(i) + "=\"" + words[i] + "\"\n";
    write_file(out / name, s);
  };
  dict("gltf.dict", {"glTF",
                     "JSON",
                     "BIN\\x00",
                     "\\\"accessors\\\"",
                     "\\\"bufferViews\\\"",
                     "\\\"buffers\\\"",
                     "\\\"byteOffset\\\"",
                     "\\\"byteStride\\\"",
                     "\\\"count\\\"",
                     "\\\"sparse\\\"",
                     "\\\"indices\\\"",
                     "\\\"componentType\\\"",
                     "5121",
                     "5123",
                     "5125",
                     "5126",
                     "\\\"normalized\\\"",
                     "\\\"mode\\\"",
                     "\\\"targets\\\"",
                     "\\\"nodes\\\"",
                     "\\\"children\\\"",
                     "\\\"matrix\\\"",
                     "\\\"VEC3\\\"",
                     "\\\"SCALAR\\\"",
                     "data:application/octet-stream;base64,",
                     "KHR_draco_mesh_compression",
                     "EXT_meshopt_compression",
                     "\\\"fallback\\\"",
                     "ATTRIBUTES",
                     "TRIANGLES",
                     "OCTAHEDRAL",
                     "EXPONENTIAL",
                     "EXT_mesh_gpu_instancing",
                     "TRANSLATION",
                     "ROTATION"});
  dict("obj.dict", {"v ", "vt ", "vn ", "f ", "/", "//", "-1", "#", "\\\\\\x0a", "g ", "o ", "usemtl ",
                    "mtllib ", "1e308", "nan", "inf", "\\x0d\\x0a", "/1/", "/-1"});
  dict("ply.dict", {"ply\\x0a",
                    "format ",
                    "ascii 1.0",
                    "binary_little_endian 1.0",
                    "binary_big_endian 1.0",
                    "element ",
                    "vertex ",
                    "face ",
                    "property ",
                    "list ",
                    "uchar ",
                    "int ",
                    "uint ",
                    "float ",
                    "double ",
                    "short ",
                    "char ",
                    "ushort ",
                    "int8 ",
                    "uint8 ",
                    "int16 ",
                    "uint32 ",
                    "float32 ",
                    "float64 ",
                    "vertex_indices",
                    "vertex_index",
                    "end_header\\x0a",
                    "comment ",
                    "obj_info ",
                    "x",
                    "y",
                    "z",
                    "nx",
                    "red",
                    "alpha",
                    "texture_u",
                    "s",
                    "\\xff\\xff\\xff\\xff"});
  dict("stl.dict", {"solid ", "facet normal ", "outer loop", "vertex ", "endloop", "endfacet", "endsolid",
                    "\\x00\\x00\\x00\\x00", "\\xff\\xff\\xff\\x7f"});
  dict("off.dict",
       {"OFF", "COFF", "NOFF", "CNOFF", "STOFF", "4OFF", "nOFF", "#", "3 ", "4 ", "-1", "1e308", "nan"});
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_seeds OUTDIR\n");
    return 2;
  }
  const fs::path out = argv[1];
  for (const char* dir : {"obj", "ply", "stl", "off", "gltf", "simplify"}) fs::create_directories(out / dir);
  serialised_seeds(out);
  handwritten_seeds(out);
  compressed_gltf_seeds(out);
  instanced_gltf_seed(out);
  simplify_seeds(out);
  dictionaries(out);
  return 0;
}
