// glTF 2.0 with pass-through (qem/gltf.h): tinygltf parses and writes the JSON and the GLB
// container and keeps every object it does not understand (extensions, extras) as values; qem
// reads primitives as Meshes and, on save, swaps in the replaced primitives' accessors and
// re-packs the binary buffer. Images are never decoded: the loader callback keeps their bytes.
//
// This is the one translation unit that compiles tiny_gltf.h's implementation.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>
// The implementation part of tiny_gltf.h is outside its include guard: the headers below include
// it again for the declarations only.
#undef TINYGLTF_IMPLEMENTATION

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <span>
#include <sstream>

#include "io/gltf_accessors.h"
#include "io/gltf_draco.h"
#include "io/gltf_meshopt.h"
#include "io/gltf_prepass.h"
#include "io/io_common.h"
#include "qem/gltf.h"
#include "quantized_borders.h"

namespace qem {

namespace {

using io::gltf::append_accessor;
using io::gltf::is_glb;
using io::gltf::read_accessor;

// Extensions that change how geometry is stored and that qem does not decode (Draco and
// EXT_meshopt_compression are decoded at load, io/gltf_draco.h and io/gltf_meshopt.h; the Khronos
// successor of the latter allows a vertex codec that Debian's meshoptimizer 0.18 predates): reading
// them as plain accessors would give garbage, so they are refused by name.
constexpr const char* kCompressed[] = {"KHR_meshopt_compression"};

// Extensions known to hold no accessor index: with any other extension in use, accessors that a
// replaced primitive leaves unused are kept as they are, since the extension may refer to them.
bool index_free_extension(const std::string& e) {
  return e.rfind("KHR_materials_", 0) == 0 || e.rfind("KHR_texture_", 0) == 0 || e == "KHR_lights_punctual" ||
         e == "KHR_mesh_quantization" || e == "EXT_texture_webp" || e == "KHR_xmp_json_ld" ||
         e == "EXT_lights_image_based";
}

// Images stay bytes: the loader keeps the decoded data: URI (a buffer view image stays in its
// buffer view and an external one keeps its URI), and the writer embeds the bytes back.
bool keep_image_bytes(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
  image->as_is = true;
  if (image->bufferView < 0 && bytes && size > 0) image->image.assign(bytes, bytes + size);
  return true;
}

bool embed_image_bytes(const std::string*, const std::string*, const tinygltf::Image* image, bool,
                       std::string* out_uri, void*) {
  if (!image->uri.empty() || image->bufferView >= 0 || image->image.empty()) return false;
  const std::string mime = image->mimeType.empty() ? "application/octet-stream" : image->mimeType;
  *out_uri = "data:" + mime + ";base64," +
             tinygltf::base64_encode(image->image.data(), static_cast<unsigned>(image->image.size()));
  return true;
}

// A file reader for in-memory parsing: nothing outside the bytes given may be read.
bool no_file(std::vector<unsigned char>*, std::string* err, const std::string& path, void*) {
  if (err) *err += "external file '" + path + "' cannot be read when parsing from memory\n";
  return false;
}
bool no_file_exists(const std::string&, void*) { return false; }
std::string same_path(const std::string& p, void*) { return p; }
bool no_write(std::string*, const std::string&, const std::vector<unsigned char>&, void*) { return false; }

std::string directory_of(const std::string& path) {
  std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

AttributeKind kind_of(const std::string& semantic) {
  if (semantic == "NORMAL") return AttributeKind::Normal;
  if (semantic == "TANGENT") return AttributeKind::Tangent;
  if (semantic.rfind("TEXCOORD_", 0) == 0) return AttributeKind::TexCoord;
  if (semantic.rfind("COLOR_", 0) == 0) return AttributeKind::Color;
  if (semantic.rfind("JOINTS_", 0) == 0) return AttributeKind::JointIndices;
  if (semantic.rfind("WEIGHTS_", 0) == 0) return AttributeKind::JointWeights;
  return AttributeKind::Scalar;
}

using Mat4 = std::array<double, 16>;  // column-major, as glTF stores matrices

Mat4 identity() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
      r[c * 4 + row] = s;
    }
  return r;
}

/// T * R * S of a translation, a unit quaternion (x, y, z, w) and a scale (glTF 2.0 §3.5.3).
Mat4 trs_matrix(const double t[3], const double q[4], const double s[3]) {
  Mat4 m = identity();
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
                       2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                       2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) m[c * 4 + row] = r[c * 3 + row] * s[c];
  std::copy(t, t + 3, m.begin() + 12);
  return m;
}

/// A node's local matrix: `matrix`, or T * R * S (glTF 2.0 §3.5.3).
Mat4 local_matrix(const tinygltf::Node& n) {
  if (n.matrix.size() == 16) {
    Mat4 m;
    std::copy(n.matrix.begin(), n.matrix.end(), m.begin());
    return m;
  }
  double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
  if (n.translation.size() == 3) std::copy(n.translation.begin(), n.translation.end(), t);
  if (n.rotation.size() == 4) std::copy(n.rotation.begin(), n.rotation.end(), q);
  if (n.scale.size() == 3) std::copy(n.scale.begin(), n.scale.end(), s);
  return trs_matrix(t, q, s);
}

/// The inverse transpose of the upper 3x3 (for normals), as a column-major 3x3.
std::array<double, 9> normal_matrix(const Mat4& m) {
  const double a = m[0], b = m[4], c = m[8], d = m[1], e = m[5], f = m[9], g = m[2], h = m[6], i = m[10];
  const double A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
  const double D = -(b * i - c * h), E = a * i - c * g, F = -(a * h - b * g);
  const double G = b * f - c * e, H = -(a * f - c * d), I = a * e - b * d;
  double det = a * A + b * B + c * C;
  if (det == 0) det = 1;
  // The cofactor matrix divided by det is the inverse transpose; row r of it maps n to n'_r.
  return {A / det, D / det, G / det, B / det, E / det, H / det, C / det, F / det, I / det};
}

/// The largest singular value of the upper 3x3 of `m`: the most it stretches a length. From the
/// largest eigenvalue of A^T A, by the closed form for symmetric 3x3 matrices (Smith 1961).
double largest_scale(const Mat4& m) {
  double b[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += m[r * 4 + k] * m[c * 4 + k];  // column r . column c
      b[r][c] = s;
    }
  const double p1 = b[0][1] * b[0][1] + b[0][2] * b[0][2] + b[1][2] * b[1][2];
  double largest = std::max({b[0][0], b[1][1], b[2][2]});
  if (p1 > 0) {
    const double q = (b[0][0] + b[1][1] + b[2][2]) / 3;
    const double p2 = (b[0][0] - q) * (b[0][0] - q) + (b[1][1] - q) * (b[1][1] - q) +
                      (b[2][2] - q) * (b[2][2] - q) + 2 * p1;
    const double p = std::sqrt(p2 / 6);
    double c[3][3];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) c[r][k] = (b[r][k] - (r == k ? q : 0)) / p;
    const double det = c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1]) -
                       c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0]) +
                       c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0]);
    const double phi = std::acos(std::clamp(det / 2, -1.0, 1.0)) / 3;
    largest = std::max(largest, q + 2 * p * std::cos(phi));
  }
  return std::sqrt(std::max(largest, 0.0));
}

/// The nodes a scene draws from: the default scene's (or the first scene's), or every node that
/// is no other's child when the file has no scene.
std::vector<int> scene_roots(const tinygltf::Model& m) {
  int scene = -1;
  if (m.defaultScene >= 0 && static_cast<std::size_t>(m.defaultScene) < m.scenes.size())
    scene = m.defaultScene;
  else if (!m.scenes.empty())
    scene = 0;
  if (scene >= 0) return m.scenes[static_cast<std::size_t>(scene)].nodes;
  std::vector<int> roots;
  std::vector<char> child(m.nodes.size(), 0);
  for (const tinygltf::Node& n : m.nodes)
    for (int c : n.children)
      if (c >= 0 && static_cast<std::size_t>(c) < child.size()) child[static_cast<std::size_t>(c)] = 1;
  for (std::size_t n = 0; n < m.nodes.size(); ++n)
    if (!child[n]) roots.push_back(static_cast<int>(n));
  return roots;
}

/// EXT_mesh_gpu_instancing: the matrices of node `n`'s instances, each T * R * S of its TRANSLATION,
/// ROTATION (renormalised: it may be quantized) and SCALE (a missing one: the identity's), applied
/// after the node's world matrix; empty when the node has none. Throws qem::Error naming `where`
/// when the accessors are not VEC3 / VEC4 / VEC3 of one count.
std::vector<Mat4> instance_matrices(const tinygltf::Model& m, const tinygltf::Node& n,
                                    const std::string& where) {
  const auto ext = n.extensions.find("EXT_mesh_gpu_instancing");
  if (ext == n.extensions.end() || !ext->second.Has("attributes")) return {};
  const tinygltf::Value& attributes = ext->second.Get("attributes");
  constexpr const char* kNames[3] = {"TRANSLATION", "ROTATION", "SCALE"};
  constexpr std::uint32_t kWidth[3] = {3, 4, 3};
  std::vector<double> values[3];
  std::size_t count = 0;
  bool any = false;
  for (int k = 0; k < 3; ++k) {
    if (!attributes.Has(kNames[k])) continue;
    const tinygltf::Value& index = attributes.Get(kNames[k]);
    const std::string at = where + " (EXT_mesh_gpu_instancing " + kNames[k] + ")";
    // (Range-checked as a double first: converting one beyond int's range is undefined.)
    const double accessor = index.IsNumber() ? index.GetNumberAsDouble() : -1;
    if (!(accessor >= 0 && accessor < double(m.accessors.size()) && accessor == std::floor(accessor)))
      throw Error(at + ": not the index of an accessor of the file");
    std::uint32_t components = 0;
    values[k] = read_accessor(m, int(accessor), at, &components);
    if (components != kWidth[k]) throw Error(at + ": not a VEC" + std::to_string(kWidth[k]));
    const std::size_t n_k = values[k].size() / components;
    if (any && n_k != count)
      throw Error(at + ": " + std::to_string(n_k) + " instances, not " + std::to_string(count));
    count = n_k, any = true;
  }
  std::vector<Mat4> out;
  out.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    if (!values[0].empty()) std::copy_n(&values[0][3 * i], 3, t);
    if (!values[1].empty()) {
      std::copy_n(&values[1][4 * i], 4, q);
      const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (len > 0)
        for (double& c : q) c /= len;
    }
    if (!values[2].empty()) std::copy_n(&values[2][3 * i], 3, s);
    out.push_back(trs_matrix(t, q, s));
  }
  return out;
}

/// World matrices of the nodes the scene draws (depth first from scene_roots, the current path
/// marked so that a cyclic, invalid hierarchy cannot loop); `reached` marks them.
std::vector<Mat4> node_world_matrices(const tinygltf::Model& m, std::vector<char>& reached) {
  std::vector<Mat4> world(m.nodes.size(), identity());
  std::vector<char> on_path(m.nodes.size(), 0);
  reached.assign(m.nodes.size(), 0);
  auto visit = [&](auto&& self, int node, const Mat4& parent) -> void {
    if (node < 0 || static_cast<std::size_t>(node) >= m.nodes.size() || on_path[static_cast<std::size_t>(node)])
      return;
    const auto n = static_cast<std::size_t>(node);
    on_path[n] = 1;
    world[n] = multiply(parent, local_matrix(m.nodes[n]));
    reached[n] = 1;
    for (int c : m.nodes[n].children) self(self, c, world[n]);
    on_path[n] = 0;
  };
  for (int r : scene_roots(m)) visit(visit, r, identity());
  return world;
}

/// Per joint of skin `s`: the matrix that takes the bind-space mesh to the world, joint world x
/// inverse bind matrix (glTF 2.0 §3.7.3: a skinned mesh is drawn by its joints; its node's own
/// transform is ignored). A joint that names no node gets the identity.
std::vector<Mat4> skin_matrices(const tinygltf::Model& m, int s, const std::vector<Mat4>& world,
                                const std::string& name) {
  const tinygltf::Skin& skin = m.skins[static_cast<std::size_t>(s)];
  std::vector<double> ibm;
  std::uint32_t components = 0;
  if (skin.inverseBindMatrices >= 0)
    ibm = read_accessor(m, skin.inverseBindMatrices, name + ": skin " + std::to_string(s) + " (inverseBindMatrices)",
                        &components);
  if (!ibm.empty() && (components != 16 || ibm.size() < 16 * skin.joints.size()))
    throw Error(name + ": skin " + std::to_string(s) + ": inverseBindMatrices is not one MAT4 per joint");
  std::vector<Mat4> out(skin.joints.size(), identity());
  for (std::size_t j = 0; j < skin.joints.size(); ++j) {
    const int joint = skin.joints[j];
    if (joint < 0 || static_cast<std::size_t>(joint) >= m.nodes.size()) continue;
    Mat4 inverse_bind = identity();
    if (!ibm.empty()) std::copy(ibm.begin() + 16 * j, ibm.begin() + 16 * (j + 1), inverse_bind.begin());
    out[j] = multiply(world[static_cast<std::size_t>(joint)], inverse_bind);
  }
  return out;
}

/// Per vertex of a skinned part: its bind pose's matrix, the sum of its joints' matrices (from
/// skin_matrices) by its weights (linear blend skinning, as renderers draw it; the weights
/// normalised). Empty when the part
/// has no JOINTS_0 and WEIGHTS_0 of four components (it is then placed by its node's matrix).
/// A vertex whose weights sum to zero keeps `fallback`.
std::vector<Mat4> blended_matrices(const Mesh& part, const std::vector<Mat4>& joints, const Mat4& fallback,
                                   const std::string& where) {
  const VertexAttribute *jw = nullptr, *ww = nullptr;
  for (const VertexAttribute& a : part.attributes) {
    if (a.name == "JOINTS_0" && a.components == 4) jw = &a;
    if (a.name == "WEIGHTS_0" && a.components == 4) ww = &a;
  }
  if (!jw || !ww) return {};
  std::vector<Mat4> out(part.vertex_count(), fallback);
  for (std::size_t v = 0; v < part.vertex_count(); ++v) {
    Mat4 sum{};
    double total = 0;
    for (int k = 0; k < 4; ++k) {
      const double w = ww->values[4 * v + k], j = jw->values[4 * v + k];
      if (w == 0) continue;
      if (!(j >= 0 && j < double(joints.size())))
        throw Error(where + " (JOINTS_0): vertex " + std::to_string(v) + " names joint " + std::to_string(j) +
                    " of a skin with " + std::to_string(joints.size()));
      for (int e = 0; e < 16; ++e) sum[e] += w * joints[static_cast<std::size_t>(j)][e];
      total += w;
    }
    // Weights sum to 1 in a valid file up to their quantization (8-bit weights to within 1/255): the
    // sum is divided out, so that a file quantized or compressed draws the same as its original.
    if (total > 0)
      for (int e = 0; e < 16; ++e) out[v][e] = sum[e] / total;
  }
  return out;
}

/// Throws unless every coordinate and attribute value fits in single precision, which glTF
/// stores (converting a double beyond the float range is undefined behaviour, and a file with
/// infinities is one no reader takes).
void check_fits_in_float(const Mesh& mesh, const std::string& where) {
  const double limit = std::numeric_limits<float>::max();
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    if (!(std::fabs(mesh.positions[i]) <= limit))
      throw Error(where + ": vertex " + std::to_string(i / 3) + " has a coordinate beyond single precision");
  for (const VertexAttribute& a : mesh.attributes)
    for (std::size_t i = 0; i < a.values.size(); ++i)
      if (!(std::fabs(a.values[i]) <= limit))
        throw Error(where + ": " + a.name + " of vertex " +
                    std::to_string(i / std::max<std::uint32_t>(a.components, 1)) +
                    " is not finite or beyond single precision");
}

}  // namespace

// A morph target's values ride along as a vertex attribute of the primitive's Mesh: named
// "target<k>/<SEMANTIC>" (no glTF semantic has a '/'), of kind Scalar (interpolated like any
// other value), and written back into the primitive's target k.
std::string morph_name(std::size_t target, const std::string& semantic) {
  return "target" + std::to_string(target) + "/" + semantic;
}

bool is_morph_name(const std::string& name) {
  const std::size_t slash = name.find('/');
  return name.rfind("target", 0) == 0 && slash != std::string::npos && slash > 6 && slash - 6 <= 9 &&
         std::all_of(name.begin() + 6, name.begin() + static_cast<std::ptrdiff_t>(slash),
                     [](char c) { return c >= '0' && c <= '9'; });
}

/// The target and semantic of a morph_name.
std::pair<std::size_t, std::string> parse_morph_name(const std::string& name) {
  const std::size_t slash = name.find('/');
  return {static_cast<std::size_t>(std::stoul(name.substr(6, slash - 6))), name.substr(slash + 1)};
}

struct GltfDocument::Impl {
  std::string name;
  tinygltf::Model model;
  std::vector<GltfPrimitiveInfo> primitives;
  std::map<std::size_t, Mesh> replaced;
  std::vector<std::string> notes;
  std::set<std::size_t> compressed_views;  // the Draco bitstreams decoded at load: not written
  // Per node, its EXT_mesh_gpu_instancing instances' matrices (instance_matrices; empty without
  // them, and for a skinned node, which its joints place), read once at load.
  std::vector<std::vector<Mat4>> node_instances;

  std::string where(std::size_t i) const {
    const GltfPrimitiveInfo& p = primitives[i];
    return name + ": mesh " + std::to_string(p.mesh) + ", primitive " + std::to_string(p.primitive);
  }
  const tinygltf::Primitive& primitive(std::size_t i) const {
    return model.meshes[primitives[i].mesh].primitives[primitives[i].primitive];
  }
  void check_and_list();
  void measure_world_scales();  // and node_instances
  Mesh read(std::size_t i) const;
  tinygltf::Model rebuilt() const;
};

namespace {

void refuse_compression(const tinygltf::Model& model, const std::string& name) {
  for (const char* ext : kCompressed) {
    bool used = std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), ext) !=
                model.extensionsUsed.end();
    for (std::size_t m = 0; m < model.meshes.size() && !used; ++m)
      for (const tinygltf::Primitive& p : model.meshes[m].primitives) used = used || p.extensions.count(ext);
    for (const tinygltf::BufferView& v : model.bufferViews) used = used || v.extensions.count(ext);
    if (used)
      throw Error(name + ": uses " + ext +
                  " (compressed geometry), which qem does not decode: decompress it first (e.g. "
                  "gltf-transform copy)");
  }
}

}  // namespace

void GltfDocument::Impl::check_and_list() {
  io::gltf::decode_meshopt(model, name);
  // Every buffer view inside its buffer, so that saving (which copies them all) cannot fail.
  for (std::size_t v = 0; v < model.bufferViews.size(); ++v) {
    const tinygltf::BufferView& view = model.bufferViews[v];
    if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size())
      throw Error(name + ": buffer view " + std::to_string(v) + " names buffer " +
                  std::to_string(view.buffer) + ", which does not exist");
    const std::size_t size = model.buffers[static_cast<std::size_t>(view.buffer)].data.size();
    if (view.byteOffset > size || view.byteLength > size - view.byteOffset)
      throw Error(name + ": buffer view " + std::to_string(v) + " (bytes " + std::to_string(view.byteOffset) +
                  ", " + std::to_string(view.byteLength) + " long) lies outside its buffer of " +
                  std::to_string(size) + " bytes");
  }
  io::gltf::PositionSteps position_steps;
  io::gltf::decode_draco(model, name, compressed_views, position_steps);
  refuse_compression(model, name);
  for (std::size_t m = 0; m < model.meshes.size(); ++m)
    for (std::size_t k = 0; k < model.meshes[m].primitives.size(); ++k) {
      const tinygltf::Primitive& p = model.meshes[m].primitives[k];
      GltfPrimitiveInfo info;
      info.mesh = m;
      info.primitive = k;
      info.material = p.material;
      info.mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
      info.morph_targets = p.targets.size();
      if (const auto step = position_steps.find({m, k}); step != position_steps.end())
        info.position_step = step->second;
      if (p.attributes.count("POSITION")) info.attributes.push_back("POSITION");
      for (const auto& [semantic, accessor] : p.attributes)
        if (semantic != "POSITION") info.attributes.push_back(semantic);
      primitives.push_back(info);
      std::size_t i = primitives.size() - 1;
      if (info.mode != TINYGLTF_MODE_TRIANGLES) {
        primitives[i].why_not =
            "mode " + std::to_string(info.mode) + " is not TRIANGLES (passed through untouched)";
      } else if (!p.attributes.count("POSITION")) {
        primitives[i].why_not = "no POSITION attribute (passed through untouched)";
      }
      // Every triangle primitive is decoded now, so that a bad file fails at load, not at save.
      if (info.mode == TINYGLTF_MODE_TRIANGLES && p.attributes.count("POSITION")) {
        Mesh mesh = read(i);
        primitives[i].vertex_count = mesh.vertex_count();
        primitives[i].face_count = mesh.face_count();
        primitives[i].simplifiable = primitives[i].why_not.empty();
      }
      if (!primitives[i].why_not.empty())
        notes.push_back(where(i) + ": not simplifiable: " + primitives[i].why_not);
    }
  measure_world_scales();
}

void GltfDocument::Impl::measure_world_scales() {
  const tinygltf::Model& m = model;
  std::vector<char> reached;
  const std::vector<Mat4> world = node_world_matrices(m, reached);
  node_instances.assign(m.nodes.size(), {});
  std::vector<double> mesh_scale(m.meshes.size(), 0);
  // Per mesh, the world matrices that draw it (sorted); a skinned mesh has none of its own.
  std::vector<std::vector<Mat4>> placed_by(m.meshes.size());
  std::vector<char> skinned(m.meshes.size(), 0);
  for (std::size_t n = 0; n < m.nodes.size(); ++n) {
    const tinygltf::Node& node = m.nodes[n];
    if (!reached[n] || node.mesh < 0 || static_cast<std::size_t>(node.mesh) >= m.meshes.size()) continue;
    const auto mesh = static_cast<std::size_t>(node.mesh);
    double scale = 0;
    if (node.skin >= 0 && static_cast<std::size_t>(node.skin) < m.skins.size()) {
      for (const Mat4& joint : skin_matrices(m, node.skin, world, name)) scale = std::max(scale, largest_scale(joint));
      skinned[mesh] = 1;
    } else {
      node_instances[n] = instance_matrices(m, node, name + ": node " + std::to_string(n));
      scale = node_instances[n].empty() ? largest_scale(world[n]) : 0;
      if (node_instances[n].empty()) placed_by[mesh].push_back(world[n]);
      for (const Mat4& instance : node_instances[n]) {
        placed_by[mesh].push_back(multiply(world[n], instance));
        scale = std::max(scale, largest_scale(placed_by[mesh].back()));
      }
    }
    double& s = mesh_scale[mesh];
    if (std::isfinite(scale)) s = std::max(s, scale);
  }
  for (GltfPrimitiveInfo& p : primitives)
    if (mesh_scale[p.mesh] > 0) p.world_scale = mesh_scale[p.mesh];
  // Meshes drawn by exactly the same world matrices (an exporter's one object split into a mesh
  // per material, each under its own node) share a placement: their primitives meet where their
  // positions are equal.
  std::map<std::vector<Mat4>, std::size_t> first_placed;
  std::vector<std::size_t> placement(m.meshes.size());
  for (std::size_t mesh = 0; mesh < m.meshes.size(); ++mesh) {
    placement[mesh] = mesh;
    // (A matrix that is not finite, from a broken file, has no order to sort or compare it by.)
    const auto finite = [](const Mat4& w) {
      return std::all_of(w.begin(), w.end(), [](double x) { return std::isfinite(x); });
    };
    if (skinned[mesh] || placed_by[mesh].empty() ||
        !std::all_of(placed_by[mesh].begin(), placed_by[mesh].end(), finite))
      continue;
    std::sort(placed_by[mesh].begin(), placed_by[mesh].end());
    placement[mesh] = first_placed.try_emplace(placed_by[mesh], mesh).first->second;
  }
  for (GltfPrimitiveInfo& p : primitives) p.placement = placement[p.mesh];
}

Mesh GltfDocument::Impl::read(std::size_t i) const {
  const tinygltf::Primitive& p = primitive(i);
  const std::string at = where(i);
  Mesh mesh;
  std::uint32_t n = 0;
  mesh.positions = read_accessor(model, p.attributes.at("POSITION"), at + " (POSITION)", &n);
  if (n != 3)
    throw Error(at + " (POSITION), accessor " + std::to_string(p.attributes.at("POSITION")) + ": not VEC3");
  const std::size_t vertices = mesh.vertex_count();
  for (double v : mesh.positions)
    if (!std::isfinite(v)) throw Error(at + " (POSITION): a coordinate is not finite");
  auto read_attribute = [&](const std::string& name, AttributeKind kind, int accessor) {
    VertexAttribute a;
    a.name = name;
    a.kind = kind;
    a.values = read_accessor(model, accessor, at + " (" + name + ")", &a.components);
    if (a.components > 4)
      throw Error(at + " (" + name + "), accessor " + std::to_string(accessor) +
                  ": a matrix, which is no vertex attribute type");
    if (a.values.size() != vertices * a.components)
      throw Error(at + " (" + name + "), accessor " + std::to_string(accessor) + ": count " +
                  std::to_string(a.values.size() / a.components) + " differs from POSITION's " +
                  std::to_string(vertices));
    for (double v : a.values)
      if (!std::isfinite(v)) throw Error(at + " (" + name + "): a value is not finite");
    mesh.attributes.push_back(std::move(a));
  };
  for (const auto& [semantic, accessor] : p.attributes) {
    // glTF's own semantics are upper case and an application's start with '_' (glTF 2.0 §3.7.2.1).
    if (is_morph_name(semantic))
      throw Error(at + ": attribute " + semantic +
                  " is no glTF semantic (qem names morph target offsets so)");
    if (semantic != "POSITION") read_attribute(semantic, kind_of(semantic), accessor);
  }
  // Morph targets' offsets (a TANGENT offset goes with the TANGENT it moves, dropped on replacing).
  for (std::size_t k = 0; k < p.targets.size(); ++k)
    for (const auto& [semantic, accessor] : p.targets[k])
      if (semantic != "TANGENT") read_attribute(morph_name(k, semantic), AttributeKind::Scalar, accessor);
  std::vector<double> idx;
  if (p.indices >= 0) {
    std::uint32_t ni = 0;
    idx = read_accessor(model, p.indices, at + " (indices)", &ni);
    const tinygltf::Accessor& ia = model.accessors[static_cast<std::size_t>(p.indices)];
    if (ni != 1 || ia.normalized ||
        (ia.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
         ia.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
         ia.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
      throw Error(at + " (indices), accessor " + std::to_string(p.indices) +
                  ": not unsigned integer scalars");
  } else {
    idx.resize(vertices);
    for (std::size_t v = 0; v < vertices; ++v) idx[v] = static_cast<double>(v);
  }
  if (idx.size() % 3 != 0)
    throw Error(at + ": " + std::to_string(idx.size()) + " indices do not make whole triangles");
  mesh.indices.reserve(idx.size());
  for (std::size_t k = 0; k < idx.size(); ++k) {
    if (idx[k] >= static_cast<double>(vertices))
      throw Error(at + " (indices), accessor " + std::to_string(p.indices) + ": index " +
                  std::to_string(static_cast<std::uint64_t>(idx[k])) + " at position " + std::to_string(k) +
                  " is not below the vertex count " + std::to_string(vertices));
    mesh.indices.push_back(static_cast<std::uint32_t>(idx[k]));
  }
  return mesh;
}

namespace {

tinygltf::TinyGLTF make_loader(bool files) {
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keep_image_bytes, nullptr);
  loader.SetImageWriter(embed_image_bytes, nullptr);
  if (!files)
    loader.SetFsCallbacks(tinygltf::FsCallbacks{no_file_exists, same_path, no_file, no_write, nullptr});
  return loader;
}

/// tinygltf's messages, one line each, as one line.
std::string one_line(std::string e) {
  while (!e.empty() && (e.back() == '\n' || e.back() == ' ')) e.pop_back();
  std::string out;
  for (char c : e) {
    if (c == '\n')
      out += "; ";
    else
      out += c;
  }
  return out;
}

}  // namespace

GltfDocument::GltfDocument() : impl_(std::make_unique<Impl>()) {}
GltfDocument::~GltfDocument() = default;
GltfDocument::GltfDocument(GltfDocument&&) noexcept = default;
GltfDocument& GltfDocument::operator=(GltfDocument&&) noexcept = default;

GltfDocument GltfDocument::load(const std::string& path) {
  io::FileData file(path);
  return from_bytes(file.bytes(), path, directory_of(path), true);
}

GltfDocument GltfDocument::parse(std::string_view bytes, const std::string& name) {
  return from_bytes(bytes, name, "", false);
}

GltfDocument GltfDocument::from_bytes(std::string_view bytes, const std::string& name,
                                      const std::string& base_dir, bool read_files) {
  if (bytes.empty()) io::fail(name, "empty file");
  if (bytes.size() >= 0xffffffffu) io::fail(name, "4 GiB or larger, which glTF does not allow");
  GltfDocument doc;
  Impl& d = *doc.impl_;
  d.name = name;
  tinygltf::TinyGLTF loader = make_loader(read_files);
  std::string err, warn;
  bool ok = false;
  try {
    const std::string prepared = io::gltf::prepare_for_tinygltf(bytes);
    if (!prepared.empty()) bytes = prepared;
    if (is_glb(bytes))
      ok = loader.LoadBinaryFromMemory(&d.model, &err, &warn,
                                       reinterpret_cast<const unsigned char*>(bytes.data()),
                                       static_cast<unsigned>(bytes.size()), base_dir);
    else
      ok = loader.LoadASCIIFromString(&d.model, &err, &warn, bytes.data(),
                                      static_cast<unsigned>(bytes.size()), base_dir);
    // tinygltf 2.7 requires a skin's inverseBindMatrices, which glTF 2.0 §5.28 makes optional (the
    // identity); skin_matrices reads a missing one so.
    for (const std::string missing = "'inverseBindMatrices' property is missing in Skin.\n";;) {
      const std::size_t at = err.find(missing);
      if (at == std::string::npos) break;
      err.erase(at, missing.size());
    }
    if (!ok || !err.empty())
      io::fail(name, err.empty() ? std::string("not a valid glTF file")
                                 : "not a valid glTF file: " + one_line(err));
    if (!warn.empty()) d.notes.push_back(name + ": " + one_line(warn));
    d.check_and_list();
  } catch (const std::bad_alloc&) {
    io::fail(name, "out of memory while reading");
  } catch (const std::length_error&) {
    io::fail(name, "out of memory while reading");
  }
  return doc;
}

const std::vector<GltfPrimitiveInfo>& GltfDocument::primitives() const { return impl_->primitives; }

std::vector<std::string> GltfDocument::notes() const { return impl_->notes; }

Mesh GltfDocument::mesh(std::size_t i) const {
  if (i >= impl_->primitives.size())
    throw Error(impl_->name + ": no primitive " + std::to_string(i) + " (the file has " +
                std::to_string(impl_->primitives.size()) + ")");
  if (!impl_->primitives[i].simplifiable)
    throw Error(impl_->where(i) + ": not simplifiable: " + impl_->primitives[i].why_not);
  if (auto it = impl_->replaced.find(i); it != impl_->replaced.end()) return it->second;
  return impl_->read(i);
}

void GltfDocument::replace(std::size_t i, Mesh mesh) {
  Impl& d = *impl_;
  Mesh old = this->mesh(i);  // checks i and simplifiable
  const std::string at = d.where(i);
  if (mesh.positions.size() % 3 != 0 || mesh.indices.size() % 3 != 0)
    throw Error(at + ": the new mesh has partial vertices or triangles");
  for (double v : mesh.positions)
    if (!std::isfinite(v)) throw Error(at + ": the new mesh has a non-finite coordinate");
  for (std::uint32_t v : mesh.indices)
    if (v >= mesh.vertex_count())
      throw Error(at + ": the new mesh has index " + std::to_string(v) + ", not below its vertex count " +
                  std::to_string(mesh.vertex_count()));
  // Same attributes by name and width; TANGENT is dropped (see gltf.h), whether given or not.
  std::erase_if(mesh.attributes, [](const VertexAttribute& a) { return a.name == "TANGENT"; });
  std::erase_if(old.attributes, [](const VertexAttribute& a) { return a.name == "TANGENT"; });
  for (const VertexAttribute& a : old.attributes) {
    auto it = std::find_if(mesh.attributes.begin(), mesh.attributes.end(),
                           [&](const VertexAttribute& b) { return b.name == a.name; });
    if (it == mesh.attributes.end()) throw Error(at + ": the new mesh lacks the attribute " + a.name);
    if (it->components != a.components)
      throw Error(at + ": the new mesh's " + a.name + " has " + std::to_string(it->components) +
                  " components, the file's " + std::to_string(a.components));
  }
  for (const VertexAttribute& b : mesh.attributes) {
    bool known = std::any_of(old.attributes.begin(), old.attributes.end(),
                             [&](const VertexAttribute& a) { return a.name == b.name; });
    if (!known)
      throw Error(at + ": the new mesh has the attribute " + b.name + ", which the primitive has not");
    if (b.values.size() != b.components * mesh.vertex_count())
      throw Error(at + ": the new mesh's " + b.name + " does not have one value per vertex and component");
    for (double v : b.values)
      if (!std::isfinite(v)) throw Error(at + ": the new mesh's " + b.name + " has a non-finite value");
  }
  check_fits_in_float(mesh, at + ": the new mesh");
  mesh.face_materials.clear();
  mesh.material_names.clear();
  mesh.vertex_properties.clear();
  if (d.primitive(i).attributes.count("TANGENT") && !d.replaced.count(i))
    d.notes.push_back(at +
                      ": TANGENT dropped on the replaced primitive (renderers compute MikkTSpace tangents)");
  std::erase(d.primitives[i].attributes, std::string("TANGENT"));
  d.primitives[i].vertex_count = mesh.vertex_count();
  d.primitives[i].face_count = mesh.face_count();
  d.replaced[i] = std::move(mesh);
}

namespace {

/// The component type a new accessor for an attribute gets: joints stay integers, other integer
/// attributes keep their unsigned type, everything else (quantized input included) is written as
/// float, which every consumer reads without KHR_mesh_quantization.
int new_component_type(const tinygltf::Model& model, int old_accessor, AttributeKind kind, bool& normalized) {
  normalized = false;
  const bool known = old_accessor >= 0 && static_cast<std::size_t>(old_accessor) < model.accessors.size();
  const int old = known ? model.accessors[static_cast<std::size_t>(old_accessor)].componentType : -1;
  const bool old_normalized = known && model.accessors[static_cast<std::size_t>(old_accessor)].normalized;
  if (kind == AttributeKind::JointIndices)
    return old == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ? old : TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
  if (kind == AttributeKind::Scalar &&
      (old == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || old == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
       (old == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT && !old_normalized))) {
    normalized = old_normalized;
    return old;
  }
  return TINYGLTF_COMPONENT_TYPE_FLOAT;
}

int index_type(std::size_t vertices) {
  // The largest value of the type is the primitive restart value, which glTF forbids in indices.
  return vertices <= 0xffff ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
}

std::vector<double> as_doubles(const std::vector<std::uint32_t>& v) { return {v.begin(), v.end()}; }

/// Which of the first `limit` buffer views an accessor (data or sparse parts) or an image uses.
std::vector<char> view_uses(const tinygltf::Model& m, std::size_t limit) {
  std::vector<char> used(limit, 0);
  auto use = [&](int v) {
    if (v >= 0 && static_cast<std::size_t>(v) < limit) used[static_cast<std::size_t>(v)] = 1;
  };
  for (const tinygltf::Accessor& a : m.accessors) {
    use(a.bufferView);
    if (a.sparse.isSparse) use(a.sparse.indices.bufferView), use(a.sparse.values.bufferView);
  }
  for (const tinygltf::Image& im : m.images) use(im.bufferView);
  return used;
}

}  // namespace

tinygltf::Model GltfDocument::Impl::rebuilt() const {
  tinygltf::Model m = model;
  const std::size_t old_accessors = m.accessors.size(), old_views = m.bufferViews.size();
  std::set<std::pair<std::size_t, std::size_t>> replaced_at;
  for (const auto& entry : replaced)
    replaced_at.insert({primitives[entry.first].mesh, primitives[entry.first].primitive});

  // 1. Who still refers to each old accessor once the replaced primitives let go of theirs.
  std::vector<int> refs(old_accessors, 0);
  std::set<int> released;
  auto ref = [&](int a) {
    if (a >= 0 && static_cast<std::size_t>(a) < old_accessors) ++refs[static_cast<std::size_t>(a)];
  };
  for (std::size_t mi = 0; mi < m.meshes.size(); ++mi)
    for (std::size_t k = 0; k < m.meshes[mi].primitives.size(); ++k) {
      const tinygltf::Primitive& p = m.meshes[mi].primitives[k];
      const bool gone = replaced_at.count({mi, k}) > 0;
      for (const auto& entry : p.attributes) gone ? (void)released.insert(entry.second) : ref(entry.second);
      gone ? (void)released.insert(p.indices) : ref(p.indices);
      for (const auto& target : p.targets)
        for (const auto& entry : target) gone ? (void)released.insert(entry.second) : ref(entry.second);
    }
  for (const tinygltf::Skin& s : m.skins) ref(s.inverseBindMatrices);
  for (const tinygltf::Animation& an : m.animations)
    for (const tinygltf::AnimationSampler& s : an.samplers) ref(s.input), ref(s.output);
  // An extension qem does not know may name accessors (EXT_mesh_gpu_instancing does): then no old
  // accessor is reused or emptied.
  const bool unknown_extensions = std::any_of(m.extensionsUsed.begin(), m.extensionsUsed.end(),
                                              [](const std::string& e) { return !index_free_extension(e); });
  std::set<int> claimed;
  // An old accessor that nothing else uses takes the new data in its slot: accessor indices stay.
  auto place = [&](tinygltf::Accessor a, int old) -> int {
    if (!unknown_extensions && old >= 0 && static_cast<std::size_t>(old) < old_accessors &&
        refs[static_cast<std::size_t>(old)] == 0 && !claimed.count(old)) {
      claimed.insert(old);
      a.name = m.accessors[static_cast<std::size_t>(old)].name;
      m.accessors[static_cast<std::size_t>(old)] = std::move(a);
      return old;
    }
    m.accessors.push_back(std::move(a));
    return static_cast<int>(m.accessors.size() - 1);
  };

  // 2. New accessors and buffer views (their bytes in `fresh`) for the replaced primitives.
  std::vector<unsigned char> fresh;
  for (const auto& [i, mesh] : replaced) {
    tinygltf::Primitive& p = m.meshes[primitives[i].mesh].primitives[primitives[i].primitive];
    std::map<std::string, int> attributes;
    auto old_of = [&](const std::string& semantic) {
      auto it = p.attributes.find(semantic);
      return it == p.attributes.end() ? -1 : it->second;
    };
    attributes["POSITION"] = place(append_accessor(m, fresh, mesh.positions, 3, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                                   false, true, TINYGLTF_TARGET_ARRAY_BUFFER),
                                   old_of("POSITION"));
    std::vector<std::map<std::string, int>> targets(p.targets.size());
    for (const VertexAttribute& va : mesh.attributes) {
      if (is_morph_name(va.name)) {  // offsets: floats (POSITION's with bounds, as glTF requires)
        const auto [k, semantic] = parse_morph_name(va.name);
        if (k >= targets.size()) continue;
        const auto old = p.targets[k].find(semantic);
        targets[k][semantic] =
            place(append_accessor(m, fresh, va.values, va.components, TINYGLTF_COMPONENT_TYPE_FLOAT, false,
                                  semantic == "POSITION", TINYGLTF_TARGET_ARRAY_BUFFER),
                  old == p.targets[k].end() ? -1 : old->second);
        continue;
      }
      bool normalized = false;
      const int type = new_component_type(model, old_of(va.name), va.kind, normalized);
      attributes[va.name] = place(append_accessor(m, fresh, va.values, va.components, type, normalized, false,
                                                  TINYGLTF_TARGET_ARRAY_BUFFER),
                                  old_of(va.name));
    }
    p.indices = place(append_accessor(m, fresh, as_doubles(mesh.indices), 1, index_type(mesh.vertex_count()),
                                      false, false, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                      p.indices);
    p.attributes = std::move(attributes);
    p.targets = std::move(targets);
    p.mode = TINYGLTF_MODE_TRIANGLES;
  }
  // Accessors that only the replaced primitives used and no new data took over (TANGENT): glTF
  // lets an accessor have no buffer view (it reads as zeros), so its index stays valid and its
  // data goes.
  if (!unknown_extensions)
    for (int a : released)
      if (a >= 0 && static_cast<std::size_t>(a) < old_accessors && refs[static_cast<std::size_t>(a)] == 0 &&
          !claimed.count(a)) {
        tinygltf::Accessor& acc = m.accessors[static_cast<std::size_t>(a)];
        acc.bufferView = -1;
        acc.byteOffset = 0;
        acc.sparse.isSparse = false;
        acc.minValues.clear();
        acc.maxValues.clear();
      }

  // 3. Buffer views: drop those only released data used (a view nothing used before, perhaps an
  // extension's, stays) and the decoded Draco bitstreams, renumber, and re-pack all bytes into
  // buffer 0.
  const std::vector<char> used_before = view_uses(model, old_views), used_after = view_uses(m, old_views);
  std::vector<int> new_index(m.bufferViews.size(), -1);
  std::vector<tinygltf::BufferView> views;
  std::vector<unsigned char> bin;
  for (std::size_t v = 0; v < m.bufferViews.size(); ++v) {
    if (v < old_views && ((used_before[v] && !used_after[v]) || compressed_views.count(v))) continue;
    tinygltf::BufferView view = m.bufferViews[v];
    const std::vector<unsigned char>* source = &fresh;
    if (v < old_views) {
      if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size() ||
          view.byteOffset > model.buffers[static_cast<std::size_t>(view.buffer)].data.size() ||
          view.byteLength >
              model.buffers[static_cast<std::size_t>(view.buffer)].data.size() - view.byteOffset)
        throw Error(name + ": buffer view " + std::to_string(v) + " lies outside its buffer");
      source = &model.buffers[static_cast<std::size_t>(view.buffer)].data;
    }
    // 4-byte alignment keeps every accessor aligned to its component size (glTF 2.0 §3.6.2.4).
    bin.resize((bin.size() + 3) & ~std::size_t(3), 0);
    const std::size_t at = bin.size();
    bin.insert(bin.end(), source->begin() + static_cast<std::ptrdiff_t>(view.byteOffset),
               source->begin() + static_cast<std::ptrdiff_t>(view.byteOffset + view.byteLength));
    view.buffer = 0;
    view.byteOffset = at;
    new_index[v] = static_cast<int>(views.size());
    views.push_back(std::move(view));
  }
  auto renumber = [&](int& v) {
    if (v >= 0 && static_cast<std::size_t>(v) < new_index.size()) v = new_index[static_cast<std::size_t>(v)];
  };
  for (tinygltf::Accessor& a : m.accessors) {
    renumber(a.bufferView);
    if (a.sparse.isSparse) renumber(a.sparse.indices.bufferView), renumber(a.sparse.values.bufferView);
  }
  for (tinygltf::Image& im : m.images) renumber(im.bufferView);
  m.bufferViews = std::move(views);
  bin.resize((bin.size() + 3) & ~std::size_t(3), 0);
  tinygltf::Buffer buffer;
  if (!m.buffers.empty()) {
    buffer.name = m.buffers[0].name;
    buffer.extras = m.buffers[0].extras;
    buffer.extensions = m.buffers[0].extensions;
  }
  buffer.data = std::move(bin);
  m.buffers.clear();
  if (!m.bufferViews.empty()) m.buffers.push_back(std::move(buffer));
  return m;
}

namespace {

std::string write_model(const tinygltf::Model& m, bool binary, const std::string& name) {
  tinygltf::TinyGLTF writer = make_loader(false);
  std::ostringstream out;
  bool ok = false;
  try {
    ok = writer.WriteGltfSceneToStream(&m, out, !binary, binary);
  } catch (const std::exception& e) {
    throw Error(name + ": cannot write glTF: " + e.what());
  }
  if (!ok) throw Error(name + ": cannot write glTF");
  return std::move(out).str();
}

std::string lower_extension(const std::string& path) {
  std::size_t slash = path.find_last_of('/'), dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string e = path.substr(dot + 1);
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

}  // namespace

std::string GltfDocument::serialize(bool binary) const {
  return write_model(impl_->rebuilt(), binary, impl_->name);
}

void GltfDocument::save(const std::string& path) const {
  const std::string e = lower_extension(path);
  if (e != "glb" && e != "gltf") throw Error(path + ": a glTF document is written as .glb or .gltf");
  std::string bytes;
  try {
    bytes = serialize(e == "glb");
  } catch (const Error& err) {
    throw Error(path + ": " + err.what());
  }
  io::write_file_atomic(path, bytes);
}

namespace {

/// The determinant of the upper 3x3 of `m`.
double determinant3(const Mat4& m) {
  return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[4] * (m[1] * m[10] - m[2] * m[9]) +
         m[8] * (m[1] * m[6] - m[2] * m[5]);
}

/// Appends a part's faces on its vertices at `base`, with their material (no material: the one
/// after the document's). A mirroring transform (negative determinant) reverses the winding
/// (glTF 2.0 §3.7.4): the node's `world`, or for a skinned part (`blended`: per vertex, from
/// blended_matrices) the skinning's at the face, the mean of its corners' matrices (linear blend
/// skinning's own transform there, but for the weights' change across the face), so that a part
/// whose joints mirror some of it keeps each face's outward side.
void add_faces(Mesh& out, const Mesh& part, std::uint32_t base, const Mat4& world,
               std::span<const Mat4> blended, int material, std::size_t materials, bool& uses_default) {
  const bool mirrored = determinant3(world) < 0;
  for (std::size_t f = 0; f < part.face_count(); ++f) {
    std::uint32_t a = part.indices[3 * f], b = part.indices[3 * f + 1], c = part.indices[3 * f + 2];
    bool flip = mirrored;
    if (!blended.empty()) {
      Mat4 sum{};
      for (std::uint32_t v : {a, b, c})
        for (int e = 0; e < 16; ++e) sum[e] += blended[v][e];
      flip = determinant3(sum) < 0;
    }
    if (flip) std::swap(b, c);
    out.indices.insert(out.indices.end(), {base + a, base + b, base + c});
  }
  if (material < 0 || static_cast<std::size_t>(material) >= materials) {
    uses_default = true;
    material = static_cast<int>(materials);
  }
  out.face_materials.insert(out.face_materials.end(), part.face_count(),
                            static_cast<std::uint32_t>(material));
}

}  // namespace

Mesh GltfDocument::scene_mesh() const {
  const Impl& d = *impl_;
  const tinygltf::Model& m = d.model;
  std::map<std::pair<std::size_t, std::size_t>, std::size_t> index_of;
  for (std::size_t i = 0; i < d.primitives.size(); ++i)
    index_of[{d.primitives[i].mesh, d.primitives[i].primitive}] = i;

  // (primitive, world matrix, node instance, skin) for every triangle primitive the scene instances.
  struct Part {
    std::size_t primitive;
    Mat4 world;
    std::size_t instance;
    int skin;
  };
  std::vector<Part> parts;
  std::size_t instances = 0;
  auto add_mesh = [&](int mesh, const Mat4& world, int skin) {
    ++instances;
    if (mesh < 0 || static_cast<std::size_t>(mesh) >= m.meshes.size()) return;
    if (skin >= 0 && static_cast<std::size_t>(skin) >= m.skins.size()) skin = -1;
    for (std::size_t k = 0; k < m.meshes[static_cast<std::size_t>(mesh)].primitives.size(); ++k) {
      std::size_t i = index_of.at({static_cast<std::size_t>(mesh), k});
      if (d.primitives[i].mode == TINYGLTF_MODE_TRIANGLES && d.primitives[i].vertex_count > 0)
        parts.push_back({i, world, instances, skin});
    }
  };
  const std::vector<int> roots = scene_roots(m);
  // Depth first with the current path marked, so that a cyclic (invalid) hierarchy cannot loop.
  std::vector<char> on_path(m.nodes.size(), 0);
  auto visit = [&](auto&& self, int node, const Mat4& parent) -> void {
    if (node < 0 || static_cast<std::size_t>(node) >= m.nodes.size() ||
        on_path[static_cast<std::size_t>(node)])
      return;
    on_path[static_cast<std::size_t>(node)] = 1;
    const tinygltf::Node& n = m.nodes[static_cast<std::size_t>(node)];
    const Mat4 world = multiply(parent, local_matrix(n));
    // EXT_mesh_gpu_instancing: the mesh once per instance (a skinned mesh follows its joints).
    const std::vector<Mat4>& instances = d.node_instances[static_cast<std::size_t>(node)];
    if (instances.empty()) add_mesh(n.mesh, world, n.skin);
    for (const Mat4& instance : instances) add_mesh(n.mesh, multiply(world, instance), n.skin);
    for (int c : n.children) self(self, c, world);
    on_path[static_cast<std::size_t>(node)] = 0;
  };
  for (int r : roots) visit(visit, r, identity());
  if (parts.empty() && m.nodes.empty())  // meshes that no node places: take them as they are
    for (std::size_t mesh = 0; mesh < m.meshes.size(); ++mesh) add_mesh(static_cast<int>(mesh), identity(), -1);
  // Refused before anything is allocated: instancing (nodes, or EXT_mesh_gpu_instancing's counts)
  // can multiply a small file into more vertices than a Mesh indexes.
  std::size_t vertices = 0;
  for (const Part& part : parts)
    if ((vertices += d.primitives[part.primitive].vertex_count) > 0xffffffffu)
      throw Error(d.name + ": the scene has more than 2^32 vertices");

  Mesh out;
  for (std::size_t mi = 0; mi < m.materials.size(); ++mi)
    out.material_names.push_back(m.materials[mi].name.empty() ? "material_" + std::to_string(mi)
                                                              : m.materials[mi].name);
  bool uses_default = false, first = true;
  // Primitives of one node instance that share their vertex accessors (one primitive per
  // material over the same vertices, as save_mesh writes) share their vertices here too.
  std::map<std::pair<std::size_t, std::map<std::string, int>>, std::uint32_t> shared_base;
  // Draco-compressed primitives of one placement joined where they meet, as simplify_document joins them
  // (quantized_borders.h): each was quantized in its own box.
  std::map<std::size_t, Mesh> snapped;
  std::set<std::size_t> compressed;  // the placements with a Draco-quantized primitive
  for (const GltfPrimitiveInfo& p : d.primitives)
    if (p.position_step > 0) compressed.insert(p.placement);
  std::vector<std::size_t> members;
  std::vector<Mesh> meshes;
  for (std::size_t i = 0; i < d.primitives.size(); ++i)
    if (compressed.count(d.primitives[i].placement) && d.primitives[i].simplifiable && !d.replaced.count(i))
      members.push_back(i), meshes.push_back(d.read(i));
  snap_quantized_primitives(meshes, members, d.primitives);
  for (std::size_t k = 0; k < members.size(); ++k) snapped[members[k]] = std::move(meshes[k]);
  std::vector<Mat4> skin_world;  // the nodes' world matrices, when a part is skinned
  std::vector<char> reached;
  std::map<int, std::vector<Mat4>> skin_joints;  // per skin: skin_matrices
  for (const Part& part_ref : parts) {
    const std::size_t i = part_ref.primitive;
    const Mat4& world = part_ref.world;
    const Mesh part = d.replaced.count(i) ? d.replaced.at(i) : snapped.count(i) ? snapped.at(i) : d.read(i);
    if (first) {
      for (const VertexAttribute& a : part.attributes)  // the rest pose: no morph offsets
        if (!is_morph_name(a.name)) out.attributes.push_back({a.name, a.kind, a.components, {}});
      first = false;
    }
    // Only the attributes every part has, with the same width, survive the merge.
    std::erase_if(out.attributes, [&](const VertexAttribute& a) {
      return !std::any_of(part.attributes.begin(), part.attributes.end(), [&](const VertexAttribute& b) {
        return b.name == a.name && b.components == a.components;
      });
    });
    const auto base = static_cast<std::uint32_t>(out.vertex_count());  // below 2^32: counted above
    // A skinned part is placed in its bind pose, each vertex by its joints' blended matrix (the
    // node's matrix when it has no joints and weights).
    std::vector<Mat4> blended;
    if (part_ref.skin >= 0) {
      if (skin_world.empty()) skin_world = node_world_matrices(m, reached);
      auto [it, fresh] = skin_joints.try_emplace(part_ref.skin);
      if (fresh) it->second = skin_matrices(m, part_ref.skin, skin_world, d.name);
      blended = blended_matrices(part, it->second, world, d.where(i));
    }
    const auto key = std::make_pair(part_ref.instance, d.primitive(i).attributes);
    if (!d.replaced.count(i)) {
      if (auto it = shared_base.find(key); it != shared_base.end()) {
        add_faces(out, part, it->second, world, blended, d.primitives[i].material, m.materials.size(),
                  uses_default);
        continue;
      }
      shared_base[key] = base;
    }
    const auto matrix_of = [&](std::size_t v) -> const Mat4& { return blended.empty() ? world : blended[v]; };
    for (std::size_t v = 0; v < part.vertex_count(); ++v) {
      const double* p = &part.positions[3 * v];
      const Mat4& w = matrix_of(v);
      for (int r = 0; r < 3; ++r) out.positions.push_back(w[r] * p[0] + w[4 + r] * p[1] + w[8 + r] * p[2] + w[12 + r]);
    }
    const std::array<double, 9> world_nm = normal_matrix(world);
    for (VertexAttribute& a : out.attributes) {
      const VertexAttribute& b = *std::find_if(part.attributes.begin(), part.attributes.end(),
                                               [&](const VertexAttribute& x) { return x.name == a.name; });
      const std::size_t start = a.values.size();
      a.values.insert(a.values.end(), b.values.begin(), b.values.end());
      if ((a.kind != AttributeKind::Normal && a.kind != AttributeKind::Tangent) || a.components < 3) continue;
      // Normals take the inverse transpose, tangents the matrix itself; both renormalised.
      for (std::size_t v = start; v < a.values.size(); v += a.components) {
        const Mat4& w = matrix_of((v - start) / a.components);
        const std::array<double, 9> nm = blended.empty() ? world_nm : normal_matrix(w);
        const double x = a.values[v], y = a.values[v + 1], z = a.values[v + 2];
        double t[3];
        for (int r = 0; r < 3; ++r)
          t[r] = a.kind == AttributeKind::Normal ? nm[r * 3] * x + nm[r * 3 + 1] * y + nm[r * 3 + 2] * z
                                                 : w[r] * x + w[4 + r] * y + w[8 + r] * z;
        const double len = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        if (len > 0)
          for (std::size_t r = 0; r < 3; ++r) a.values[v + r] = t[r] / len;
      }
    }
    add_faces(out, part, base, world, blended, d.primitives[i].material, m.materials.size(), uses_default);
  }
  if (uses_default) out.material_names.push_back("(default)");
  // Node matrices are unchecked numbers: a huge scale can push a coordinate to infinity.
  for (double v : out.positions)
    if (!std::isfinite(v)) throw Error(d.name + ": a node transform makes a coordinate non-finite");
  for (const VertexAttribute& a : out.attributes)
    for (double v : a.values)
      if (!std::isfinite(v))
        throw Error(d.name + ": a node transform makes a " + a.name + " value non-finite");
  return out;
}

std::string serialize_gltf(const Mesh& mesh, bool binary) {
  check_fits_in_float(mesh, "cannot write glTF");
  tinygltf::Model m;
  m.asset.version = "2.0";
  m.asset.generator = "qem";
  std::vector<unsigned char> bin;
  if (mesh.face_count() > 0) {
    tinygltf::Primitive shared;
    shared.mode = TINYGLTF_MODE_TRIANGLES;
    m.accessors.push_back(append_accessor(m, bin, mesh.positions, 3, TINYGLTF_COMPONENT_TYPE_FLOAT, false,
                                          true, TINYGLTF_TARGET_ARRAY_BUFFER));
    shared.attributes["POSITION"] = 0;
    int texcoords = 0, colors = 0;
    for (const VertexAttribute& a : mesh.attributes) {
      // The glTF semantic for the attribute's kind and width; anything else is an application
      // attribute, whose name must start with '_' (glTF 2.0 §3.7.2.1).
      std::string semantic;
      switch (a.kind) {
        case AttributeKind::Normal:
          if (a.components == 3) semantic = "NORMAL";
          break;
        case AttributeKind::TexCoord:
          if (a.components == 2) semantic = "TEXCOORD_" + std::to_string(texcoords++);
          break;
        case AttributeKind::Color:
          if (a.components >= 3) semantic = "COLOR_" + std::to_string(colors++);
          break;
        case AttributeKind::JointIndices:
        case AttributeKind::JointWeights:
          continue;  // joints without a skin mean nothing (GltfDocument keeps skins)
        case AttributeKind::Tangent:
          if (a.components == 4) semantic = "TANGENT";
          break;
        case AttributeKind::Scalar:
          break;
      }
      if (semantic.empty()) semantic = a.name.rfind('_', 0) == 0 ? a.name : "_" + a.name;
      if (shared.attributes.count(semantic) || a.components < 1 || a.components > 4 ||
          a.values.size() != a.components * mesh.vertex_count())
        continue;
      m.accessors.push_back(append_accessor(m, bin, a.values, a.components, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                            false, false, TINYGLTF_TARGET_ARRAY_BUFFER));
      shared.attributes[semantic] = static_cast<int>(m.accessors.size() - 1);
    }
    // One primitive per material, all on the same vertex accessors.
    std::map<std::uint32_t, std::vector<double>> faces;
    for (std::size_t f = 0; f < mesh.face_count(); ++f) {
      const std::uint32_t mat = f < mesh.face_materials.size() ? mesh.face_materials[f] : 0;
      faces[mat].insert(faces[mat].end(), mesh.indices.begin() + static_cast<std::ptrdiff_t>(3 * f),
                        mesh.indices.begin() + static_cast<std::ptrdiff_t>(3 * f + 3));
    }
    const bool with_materials = !mesh.face_materials.empty() || !mesh.material_names.empty();
    tinygltf::Mesh gm;
    for (const auto& [mat, idx] : faces) {
      tinygltf::Primitive p = shared;
      m.accessors.push_back(append_accessor(m, bin, idx, 1, index_type(mesh.vertex_count()), false, false,
                                            TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER));
      p.indices = static_cast<int>(m.accessors.size() - 1);
      if (with_materials) {
        while (m.materials.size() <= mat) {
          tinygltf::Material material;
          const std::size_t k = m.materials.size();
          material.name =
              k < mesh.material_names.size() ? mesh.material_names[k] : "material_" + std::to_string(k);
          m.materials.push_back(std::move(material));
        }
        p.material = static_cast<int>(mat);
      }
      gm.primitives.push_back(std::move(p));
    }
    m.meshes.push_back(std::move(gm));
    tinygltf::Node node;
    node.mesh = 0;
    m.nodes.push_back(node);
    tinygltf::Scene scene;
    scene.nodes = {0};
    m.scenes.push_back(scene);
    m.defaultScene = 0;
    bin.resize((bin.size() + 3) & ~std::size_t(3), 0);
    tinygltf::Buffer buffer;
    buffer.data = std::move(bin);
    m.buffers.push_back(std::move(buffer));
  }
  return write_model(m, binary, "glTF");
}

}  // namespace qem
