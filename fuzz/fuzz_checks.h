// What the fuzzers check, shared with tests/fuzz_regressions_test.cpp so that a crash input found by
// a fuzzer replays as a plain unit test (built with any compiler, no libFuzzer needed).
//
//  - check_mesh: the guarantees of io.h on a parsed mesh (valid indices, finite coordinates, one
//    property value per vertex).
//  - check_parse: parse, check, write back in every variant, read again.
//  - decode_simplify_case: turns arbitrary bytes into a small mesh plus SimplifyOptions. Our own
//    byte reader rather than libFuzzer's FuzzedDataProvider, so the decoding is identical in the
//    fuzzer and in the GCC-built regression tests.
//  - check_simplify_result: the guarantees of simplify.h on the output.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "qem/error.h"
#include "qem/io.h"
#include "qem/mesh.h"
#include "qem/simplify.h"

namespace qem::fuzz {

/// "" when `m` keeps the reader's promises, else what is wrong.
inline std::string check_mesh(const Mesh& m) {
  if (m.positions.size() % 3 != 0) return "positions.size() is not a multiple of 3";
  if (m.indices.size() % 3 != 0) return "indices.size() is not a multiple of 3";
  const std::size_t nv = m.vertex_count();
  for (std::size_t i = 0; i < m.indices.size(); ++i)
    if (m.indices[i] >= nv)
      return "face " + std::to_string(i / 3) + " index " + std::to_string(m.indices[i]) +
             " >= " + std::to_string(nv) + " vertices";
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    if (!std::isfinite(m.positions[i])) return "vertex " + std::to_string(i / 3) + " is not finite";
  for (const VertexProperty& p : m.vertex_properties)
    if (p.values.size() != nv)
      return "property " + p.name + " has " + std::to_string(p.values.size()) + " values for " +
             std::to_string(nv) + " vertices";
  for (const VertexAttribute& a : m.attributes) {
    if (a.components < 1 || a.components > 4 || a.values.size() != std::size_t{a.components} * nv)
      return "attribute " + a.name + " has " + std::to_string(a.values.size()) + " values for " +
             std::to_string(nv) + " vertices of " + std::to_string(a.components) + " components";
    for (double v : a.values)
      if (!std::isfinite(v)) return "attribute " + a.name + " has a non-finite value";
  }
  if (!m.face_materials.empty() && m.face_materials.size() != m.face_count())
    return "face_materials is not one per face";
  for (std::uint32_t f : m.face_materials)
    if (f >= m.material_names.size()) return "face material " + std::to_string(f) + " has no name";
  return "";
}

/// Each face corner's position and attribute values: what a round trip must keep however the
/// writer numbers vertices (an OBJ with vt/vn is welded on write and read back as wedges).
inline std::vector<double> corner_values(const Mesh& m) {
  std::vector<double> r;
  for (std::uint32_t v : m.indices) {
    r.insert(r.end(), m.positions.begin() + 3 * v, m.positions.begin() + 3 * v + 3);
    for (const VertexAttribute& a : m.attributes)
      r.insert(r.end(), a.values.begin() + a.components * v, a.values.begin() + a.components * (v + 1));
  }
  return r;
}

/// Every way a mesh can be written in `format`: text and binary (PLY, STL; glTF .gltf and .glb),
/// and for PLY float and double values. The fuzzers' round trips and seeds go through all of them.
inline std::vector<SaveOptions> save_variants(FileFormat format) {
  std::vector<SaveOptions> variants;
  for (bool binary : {false, true})
    for (bool double_precision : {false, true}) {
      if (binary && format != FileFormat::Ply && format != FileFormat::Stl && format != FileFormat::Gltf)
        continue;
      if (double_precision && format != FileFormat::Ply) continue;
      SaveOptions o;
      o.format = format;
      o.binary = binary;
      o.double_precision = double_precision;
      variants.push_back(o);
    }
  return variants;
}

/// Parses `bytes` as `format`. A qem::Error from the reader is the documented rejection and gives
/// "". Otherwise the mesh must pass check_mesh, and what the writers write must read back with the
/// same face count (and the same coordinates, where the variant is lossless). Returns "" or what
/// is wrong; exceptions other than qem::Error propagate.
inline std::string check_parse(std::string_view bytes, FileFormat format) {
  LoadOptions options;
  options.format = format;
  options.keep_vertex_properties = true;  // exercise the property paths too
  Mesh mesh;
  try {
    mesh = parse_mesh(bytes, format, "fuzz", options);
  } catch (const Error&) {
    return "";
  }
  std::string problem = check_mesh(mesh);
  if (!problem.empty()) return problem;
  // A writer may refuse with qem::Error (a PLY property name it cannot write, a coordinate beyond
  // float range).
  for (const SaveOptions& o : save_variants(format)) {
    std::string out;
    try {
      out = serialize_mesh(mesh, o);
    } catch (const Error&) {
      continue;
    }
    Mesh again;
    try {
      again = parse_mesh(out, format, "fuzz-roundtrip", options);
    } catch (const Error& e) {
      return std::string("re-reading the written mesh failed: ") + e.what();
    }
    if (again.face_count() != mesh.face_count())
      return "a write/read round trip changed the face count from " + std::to_string(mesh.face_count()) +
             " to " + std::to_string(again.face_count());
    // A double PLY, OBJ and OFF keep every coordinate exactly (shortest round-trip text or the
    // raw bits); float formats keep them to float precision.
    const bool wedges = format == FileFormat::Obj && (mesh.find_attribute(AttributeKind::TexCoord) ||
                                                      mesh.find_attribute(AttributeKind::Normal));
    if (wedges) {
      // Vertices may be renumbered (duplicate v lines are welded); every vertex and corner stays.
      if (again.vertex_count() != mesh.vertex_count())
        return "an OBJ round trip changed the vertex count from " + std::to_string(mesh.vertex_count()) +
               " to " + std::to_string(again.vertex_count());
      if (corner_values(again) != corner_values(mesh)) return "an OBJ round trip changed a corner's values";
    } else if (o.double_precision || format == FileFormat::Obj || format == FileFormat::Off) {
      if (again.positions != mesh.positions) return "a lossless write/read round trip changed a coordinate";
    }
  }
  return "";
}

/// Reads little pieces of an input; past the end it yields zeros, so every input decodes.
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  std::uint16_t u16() { return std::uint16_t(byte() | (std::uint16_t(byte()) << 8)); }
  std::uint64_t u64() {
    std::uint64_t v = 0;
    for (int k = 0; k < 8; ++k) v |= std::uint64_t(byte()) << (8 * k);
    return v;
  }
  bool flag() { return byte() & 1; }
  /// A uniform-ish value in [lo, hi].
  double in_range(double lo, double hi) { return lo + (hi - lo) * (u16() / 65535.0); }
  bool empty() const { return pos_ >= size_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

struct SimplifyCase {
  Mesh mesh;
  SimplifyOptions options;
};

/// A coordinate in one of three flavours: a coarse lattice (coincident, collinear and coplanar
/// points are likely, the degenerate cases of GH97 §4), a fine one, or raw finite doubles whose
/// magnitude is capped so that quadric products (fourth powers) cannot overflow.
inline double decode_coordinate(ByteReader& in, int flavour) {
  switch (flavour) {
    case 0:
      return (int(in.byte() % 9) - 4) * 0.5;
    case 1:
      return in.in_range(-1000, 1000);
    default: {
      std::uint64_t bits = in.u64();
      double x;
      std::memcpy(&x, &bits, sizeof x);
      if (!std::isfinite(x) || std::fabs(x) > 1e15) x = std::fmod(double(bits >> 11), 2e6) - 1e6;
      return x;
    }
  }
}

inline SimplifyCase decode_simplify_case(const std::uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  SimplifyCase c;
  // --- options first, so that a short input still varies them ------------------------------------
  SimplifyOptions& o = c.options;
  const std::uint8_t targets = in.byte();
  const std::uint8_t nf_hint = in.byte();
  if (targets & 1) o.target_faces = in.byte() % (nf_hint % 128 + 2);
  if (targets & 2) o.target_ratio = in.byte() / 255.0;
  if (targets & 4) o.target_vertices = in.byte() % 40;
  if (targets & 8) {
    o.max_error = in.in_range(0, 2);
    o.max_error_is_relative = in.flag();
  }
  if (!(targets & 15)) o.target_ratio = 0.5;  // something to do
  o.weighting = static_cast<Weighting>(in.byte() % 3);
  o.placement = static_cast<Placement>(in.byte() % 4);
  const std::uint8_t misc = in.byte();
  if (misc & 1) {
    o.threshold = in.in_range(0, 1.5);
    o.threshold_is_relative = misc & 2;
  }
  static const double kBoundaryWeights[] = {0, 1, 1000, 1e8};
  o.boundary_weight = kBoundaryWeights[(misc >> 2) & 3];
  o.lock_border = misc & 16;
  o.preserve_topology = misc & 32;
  if (misc & 64) o.refit_rounds = misc & 128 ? 3 : 1;  // the refit after the contractions (qem/refit.h)
  o.inversion = static_cast<InversionPolicy>(in.byte() % 3);
  o.max_normal_turn_degrees = in.in_range(1, 89.9);
  // Now and then an invalid option: simplify must throw qem::Error, not misbehave.
  if ((misc & 0xC0) == 0xC0) {
    switch (in.byte() % 4) {
      case 0:
        o.target_ratio = -0.5;
        break;
      case 1:
        o.max_normal_turn_degrees = 120;
        break;
      case 2:
        o.threshold = -1;
        break;
      default:
        o.max_error = std::numeric_limits<double>::quiet_NaN();
        break;
    }
  }

  // --- the mesh: up to 64 vertices and 127 faces, all indices in range ----------------------------
  const int flavour = in.byte() % 3;
  const std::size_t nv = 3 + in.byte() % 62;
  for (std::size_t v = 0; v < nv; ++v)
    for (int k = 0; k < 3; ++k) c.mesh.positions.push_back(decode_coordinate(in, flavour));
  const std::size_t nf = nf_hint % 128;
  for (std::size_t f = 0; f < nf && !in.empty(); ++f) {
    // Mostly faces near the previous one, so the faces share edges and form surfaces.
    std::uint32_t base = std::uint32_t(in.byte() % nv);
    std::uint8_t spread = in.byte();
    for (int k = 0; k < 3; ++k)
      c.mesh.indices.push_back(std::uint32_t((base + (spread & 0x80 ? in.byte() : in.byte() % 4)) % nv));
  }
  return c;
}

/// "" when the result keeps simplify.h's promises, else what is wrong.
inline std::string check_simplify_result(const SimplifyCase& c, const SimplifyResult& r) {
  std::string mesh_problem = check_mesh(r.mesh);
  if (!mesh_problem.empty()) return "output: " + mesh_problem;
  const Mesh& m = r.mesh;
  if (m.face_count() > c.mesh.face_count()) return "more output faces than input faces";
  std::vector<std::uint8_t> used(m.vertex_count(), 0);
  for (std::size_t f = 0; f < m.face_count(); ++f) {
    const std::uint32_t* t = &m.indices[3 * f];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
      return "output face " + std::to_string(f) + " has a repeated index";
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
  }
  for (std::size_t v = 0; v < used.size(); ++v)
    if (!used[v]) return "output vertex " + std::to_string(v) + " is unreferenced";
  if (!(r.max_error >= 0)) return "max_error is negative or NaN";
  if (r.refit_rounds > 0 && !(r.refit_rms_after <= r.refit_rms_before))
    return "the refit raised its own error";
  return "";
}

}  // namespace qem::fuzz
