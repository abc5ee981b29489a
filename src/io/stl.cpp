// STL, ASCII and binary. Binary vs ASCII is decided by size: a binary file is exactly
// 84 + 50 * n bytes for the n of its header, and many binary exporters start the 80-byte header
// with "solid", so the keyword alone cannot be trusted. Every triangle gets its own three corners;
// mesh_io.cpp welds them afterwards (Weld::Auto).
#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "io/io_common.h"
#include "io/weld.h"

namespace qem::io {

namespace {

std::uint32_t load_u32le(const unsigned char* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  if constexpr (std::endian::native == std::endian::big) v = __builtin_bswap32(v);
  return v;
}

float load_f32le(const unsigned char* p) { return std::bit_cast<float>(load_u32le(p)); }

bool starts_with_solid(std::string_view bytes) {
  std::size_t i = 0;
  while (i < bytes.size() && (bytes[i] == ' ' || bytes[i] == '\t' || bytes[i] == '\r' || bytes[i] == '\n'))
    ++i;
  return bytes.substr(i, 5) == "solid";
}

/// Collects triangle corners either welded on the fly (the usual case: the unwelded soup, 9
/// doubles per triangle, is never built) or as the raw soup (Weld::Off).
class CornerSink {
 public:
  CornerSink(Mesh& mesh, bool weld, std::size_t expected_triangles)
      : mesh_(mesh), weld_(weld), welder_(mesh.positions, weld ? expected_triangles / 2 + 16 : 0) {
    mesh_.positions.reserve(3 * (weld ? expected_triangles / 2 + 16 : 3 * expected_triangles));
    mesh_.indices.reserve(3 * expected_triangles);
  }
  [[gnu::always_inline]] void prefetch(double x, double y, double z) const {  // see VertexWelder::prefetch
    if (weld_) welder_.prefetch(x, y, z);
  }
  std::uint32_t add(double x, double y, double z) {
    if (weld_) return welder_.add(x, y, z);
    const auto index = static_cast<std::uint32_t>(mesh_.positions.size() / 3);
    mesh_.positions.push_back(x);
    mesh_.positions.push_back(y);
    mesh_.positions.push_back(z);
    return index;
  }
  std::size_t corners = 0;  ///< corners added, to report how many were welded away

 private:
  Mesh& mesh_;
  bool weld_;
  VertexWelder welder_;
};

Mesh parse_binary(std::string_view bytes, const std::string& name, bool weld, std::size_t& welded) {
  const auto* base = reinterpret_cast<const unsigned char*>(bytes.data());
  const std::uint64_t n = load_u32le(base + 80);
  if (n == 0) fail(name, "binary STL with no triangles");
  Mesh mesh;
  CornerSink sink(mesh, weld, static_cast<std::size_t>(n));
  const unsigned char* t = base + 84;
  constexpr std::uint64_t kAhead = 8;  // triangles between prefetch and use
  for (std::uint64_t i = 0; i < n; ++i, t += 50) {
    if (i + kAhead < n)
      for (int c = 0; c < 3; ++c) {
        const unsigned char* q = t + 50 * kAhead + 12 + 12 * c;
        sink.prefetch(load_f32le(q), load_f32le(q + 4), load_f32le(q + 8));
      }
    // 12 bytes of normal (recomputed by whoever needs it), then 3 corners, then 2 attribute bytes.
    for (int c = 0; c < 3; ++c) {
      const unsigned char* q = t + 12 + 12 * c;
      double x = load_f32le(q), y = load_f32le(q + 4), z = load_f32le(q + 8);
      if (!finite3(x, y, z)) fail_element(name, "triangle", i, "vertex coordinate is not finite");
      mesh.indices.push_back(sink.add(x, y, z));
    }
  }
  welded = 3 * n - mesh.vertex_count();
  return mesh;
}

Mesh parse_ascii(std::string_view bytes, const std::string& name, bool weld, std::size_t& welded) {
  Mesh mesh;
  // An ASCII facet takes well over 100 bytes; size the tables from that, bounded by the data.
  CornerSink sink(mesh, weld, bytes.size() / 128 + 16);
  TextCursor in(bytes, name, 0, false);
  std::size_t total = 0;
  std::uint32_t facet[3];
  std::size_t corners = 0;  // corners of the current facet
  bool in_loop = false;
  while (in.skip_space()) {
    std::string_view w = in.word();
    if (w == "solid" || w == "endsolid") {
      in.next_line();  // the solid's name, if any
    } else if (w == "facet" || w == "endfacet" || w == "outer") {
      // "facet normal nx ny nz": the normal is recomputed from the corners when needed.
    } else if (w == "normal") {
      for (int k = 0; k < 3; ++k) {
        if (!in.skip_space()) in.fail("unexpected end of file in a facet normal");
        in.number("a normal component");
      }
    } else if (w == "loop") {
      if (in_loop) in.fail("'loop' inside a loop");
      in_loop = true;
      corners = 0;
    } else if (w == "vertex") {
      if (!in_loop) in.fail("'vertex' outside 'outer loop'");
      double c[3];
      for (double& v : c) {
        if (!in.skip_space()) in.fail("unexpected end of file in a vertex");
        float f;  // STL coordinates are single precision, in ASCII files too
        if (!in.try_number(f)) in.fail_expected("a vertex coordinate");
        v = f;
      }
      if (!finite3(c[0], c[1], c[2])) in.fail("vertex coordinate is not finite");
      if (mesh.vertex_count() >= 0xFFFFFFFEull) in.fail("too many vertices");
      std::uint32_t v = sink.add(c[0], c[1], c[2]);
      ++total;
      // Polygonal facets (rare) are fanned: keep the first corner and the previous one.
      if (corners < 3) {
        facet[corners] = v;
        if (corners == 2) mesh.indices.insert(mesh.indices.end(), facet, facet + 3);
      } else {
        mesh.indices.push_back(facet[0]);
        mesh.indices.push_back(facet[2]);
        mesh.indices.push_back(v);
        facet[2] = v;
      }
      ++corners;
    } else if (w == "endloop") {
      if (!in_loop) in.fail("'endloop' without 'outer loop'");
      if (corners < 3) in.fail("facet with " + std::to_string(corners) + " vertices (at least 3 needed)");
      in_loop = false;
    } else {
      std::string shown;
      for (char c : w.substr(0, 24)) shown += (static_cast<unsigned char>(c) >= 32 && c < 127) ? c : '?';
      in.fail("unexpected '" + shown + "' in ASCII STL");
    }
  }
  if (in_loop) in.fail("unexpected end of file inside a facet");
  if (mesh.indices.empty()) fail(name, "no faces");
  welded = total - mesh.vertex_count();
  return mesh;
}

}  // namespace

bool stl_is_binary(std::string_view bytes) {
  if (bytes.size() < 84) return false;
  const std::uint64_t n = load_u32le(reinterpret_cast<const unsigned char*>(bytes.data()) + 80);
  return bytes.size() == 84 + 50 * n;
}

Mesh parse_stl(std::string_view bytes, const std::string& name, const LoadOptions& options,
               LoadReport& report) {
  if (bytes.empty()) fail(name, "empty file");
  report.format = FileFormat::Stl;
  const bool weld = options.weld != Weld::Off;  // Auto welds STL
  if (stl_is_binary(bytes)) {
    report.binary = true;
    return parse_binary(bytes, name, weld, report.vertices_welded);
  }
  if (starts_with_solid(bytes)) {
    // A binary file that lies about its count would also start with "solid" sometimes; if the
    // ASCII parse fails on non-text bytes the error says where.
    report.binary = false;
    return parse_ascii(bytes, name, weld, report.vertices_welded);
  }
  if (bytes.size() < 84)
    fail(name, "too short for a binary STL (" + std::to_string(bytes.size()) + " bytes)");
  const std::uint64_t n = load_u32le(reinterpret_cast<const unsigned char*>(bytes.data()) + 80);
  const std::uint64_t have = (bytes.size() - 84) / 50;
  fail_element(name, "triangle", std::min(n, have),
               "binary STL header declares " + std::to_string(n) + " triangles (" +
                   std::to_string(84 + 50 * n) + " bytes) but the file has " + std::to_string(bytes.size()) +
                   " bytes");
}

std::string write_stl(const Mesh& mesh, bool binary) {
  const std::size_t nf = mesh.face_count();
  if (nf > 0xFFFFFFFFull) throw Error("cannot write binary STL: more than 2^32 triangles");
  check_fits_in_float(mesh, false, "STL");
  auto normal = [&](std::size_t f, float n[3]) {
    const double* a = &mesh.positions[3 * std::size_t{mesh.indices[3 * f]}];
    const double* b = &mesh.positions[3 * std::size_t{mesh.indices[3 * f + 1]}];
    const double* c = &mesh.positions[3 * std::size_t{mesh.indices[3 * f + 2]}];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double w[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    double len = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (int k = 0; k < 3; ++k) n[k] = len > 0 ? static_cast<float>(w[k] / len) : 0.0f;
  };
  std::string out;
  if (binary) {
    out.resize(84 + 50 * nf, '\0');
    // The header must not begin with "solid", or size-unaware readers take the file for ASCII.
    const char header[] = "binary STL written by qem";
    std::memcpy(out.data(), header, sizeof header - 1);
    auto put32 = [&](std::size_t at, std::uint32_t v) {
      if constexpr (std::endian::native == std::endian::big) v = __builtin_bswap32(v);
      std::memcpy(out.data() + at, &v, 4);
    };
    put32(80, static_cast<std::uint32_t>(nf));
    for (std::size_t f = 0; f < nf; ++f) {
      float n[3];
      normal(f, n);
      std::size_t at = 84 + 50 * f;
      for (int k = 0; k < 3; ++k) put32(at + 4 * k, std::bit_cast<std::uint32_t>(n[k]));
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k)
          put32(at + 12 + 12 * c + 4 * k, std::bit_cast<std::uint32_t>(static_cast<float>(
                                              mesh.positions[3 * std::size_t{mesh.indices[3 * f + c]} + k])));
    }
    return out;
  }
  out.reserve(nf * 200 + 32);
  out += "solid qem\n";
  for (std::size_t f = 0; f < nf; ++f) {
    float n[3];
    normal(f, n);
    out += "facet normal ";
    for (int k = 0; k < 3; ++k) {
      append_number(out, n[k]);
      out += k < 2 ? ' ' : '\n';
    }
    out += " outer loop\n";
    for (int c = 0; c < 3; ++c) {
      out += "  vertex ";
      for (int k = 0; k < 3; ++k) {
        append_number(out, static_cast<float>(mesh.positions[3 * std::size_t{mesh.indices[3 * f + c]} + k]));
        out += k < 2 ? ' ' : '\n';
      }
    }
    out += " endloop\nendfacet\n";
  }
  out += "endsolid qem\n";
  return out;
}

}  // namespace qem::io
