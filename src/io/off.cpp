// Object File Format (Geomview OFF) and its prefixed variants: [ST][C][N][4]OFF. Comments start
// with '#'; the counts may share the header line; each vertex row and face row may carry extra
// values (normals, colours, texture coordinates, face colours) after the ones we need, which are
// skipped up to the end of the row's line.
#include <string>
#include <vector>

#include "io/io_common.h"

namespace qem::io {

namespace {

struct OffHeader {
  bool homogeneous = false;  // 4OFF: x y z w
};

bool parse_keyword(std::string_view w, OffHeader& h) {
  // Prefixes in their canonical order: ST (texture), C (colour), N (normal), 4 (homogeneous).
  if (w.substr(0, 2) == "ST") w.remove_prefix(2);
  if (w.substr(0, 1) == "C") w.remove_prefix(1);
  if (w.substr(0, 1) == "N") w.remove_prefix(1);
  if (w.substr(0, 1) == "4") {
    h.homogeneous = true;
    w.remove_prefix(1);
  }
  return w == "OFF";
}

}  // namespace

Mesh parse_off(std::string_view bytes, const std::string& name, const LoadOptions&, LoadReport& report) {
  if (bytes.empty()) fail(name, "empty file");
  TextCursor in(bytes, name, '#', false);
  OffHeader h;
  if (!in.skip_space()) fail(name, "no OFF header (file has only comments or whitespace)");
  std::string_view kw = in.word();
  if (!parse_keyword(kw, h)) {
    if (kw.substr(0, 4) == "nOFF" || kw.find("nOFF") != std::string_view::npos)
      in.fail("n-dimensional nOFF is not supported");
    in.fail("not an OFF file (expected an 'OFF' header)");
  }
  in.skip_blank();
  if (in.starts_with("BINARY")) in.fail("binary OFF is not supported");

  // Counts: on the header line or the next non-comment line; the edge count is optional.
  long long counts[2];
  for (long long& c : counts) {
    if (!in.skip_space()) in.fail("unexpected end of file in the vertex/face counts");
    c = in.integer("a count");
    if (c < 0) in.fail("negative count " + std::to_string(c));
  }
  in.next_line();
  const std::uint64_t nv = static_cast<std::uint64_t>(counts[0]), nf = static_cast<std::uint64_t>(counts[1]);
  const std::uint64_t left =
      static_cast<std::uint64_t>(bytes.size() - static_cast<std::size_t>(in.pos() - bytes.data()));
  // A vertex row takes at least 6 bytes ("0 0 0\n"), a face row at least 8 ("3 0 0 0\n").
  if (!fits(nv, 6, left + 1))
    in.fail("header declares " + std::to_string(nv) + " vertices but the file is too short");
  if (!fits(nf, 8, left + 1))
    in.fail("header declares " + std::to_string(nf) + " faces but the file is too short");
  if (nv > 0xFFFFFFFFull) in.fail("too many vertices for 32-bit indices");

  Mesh mesh;
  mesh.positions.resize(3 * nv);
  for (std::uint64_t i = 0; i < nv; ++i) {
    double c[4] = {0, 0, 0, 1};
    for (int k = 0; k < (h.homogeneous ? 4 : 3); ++k) {
      if (!in.skip_space())
        in.fail("unexpected end of file: vertex " + std::to_string(i) + " of " + std::to_string(nv));
      c[k] = in.number("a vertex coordinate");
    }
    if (h.homogeneous) {
      if (c[3] == 0) in.fail("homogeneous vertex with w = 0");
      for (int k = 0; k < 3; ++k) c[k] /= c[3];
    }
    if (!finite3(c[0], c[1], c[2])) in.fail("vertex coordinate is not finite");
    for (int k = 0; k < 3; ++k) mesh.positions[3 * i + k] = c[k];
    in.next_line();  // normals, colours, texture coordinates
  }

  mesh.indices.reserve(3 * nf);
  PolygonSink sink{&mesh.indices};
  std::vector<std::uint32_t> corners;
  for (std::uint64_t f = 0; f < nf; ++f) {
    if (!in.skip_space())
      in.fail("unexpected end of file: face " + std::to_string(f) + " of " + std::to_string(nf));
    long long k = in.integer("a face vertex count");
    if (k < 3) in.fail("face with " + std::to_string(k) + " vertices (at least 3 needed)");
    const std::uint64_t rest =
        static_cast<std::uint64_t>(bytes.size() - static_cast<std::size_t>(in.pos() - bytes.data()));
    if (!fits(static_cast<std::uint64_t>(k), 2, rest + 1))
      in.fail("face vertex count " + std::to_string(k) + " exceeds the data left in the file");
    corners.clear();
    for (long long j = 0; j < k; ++j) {
      if (!in.skip_space()) in.fail("unexpected end of file in face " + std::to_string(f));
      long long v = in.integer("a vertex index");
      if (v < 0 || static_cast<std::uint64_t>(v) >= nv)
        in.fail("vertex index " + std::to_string(v) + " out of range (" + std::to_string(nv) + " vertices)");
      corners.push_back(static_cast<std::uint32_t>(v));
    }
    sink.add(corners.data(), corners.size());
    in.next_line();  // face colour
  }
  if (mesh.indices.empty()) fail(name, "no faces");
  report.format = FileFormat::Off;
  report.binary = false;
  report.polygons_triangulated = sink.polygons;
  return mesh;
}

std::string write_off(const Mesh& mesh) {
  std::string out;
  out.reserve(mesh.positions.size() * 12 + mesh.indices.size() * 8 + 32);
  out += "OFF\n";
  append_uint(out, mesh.vertex_count());
  out += ' ';
  append_uint(out, mesh.face_count());
  out += " 0\n";
  for (std::size_t i = 0; i < mesh.positions.size(); i += 3) {
    append_number(out, mesh.positions[i]);
    out += ' ';
    append_number(out, mesh.positions[i + 1]);
    out += ' ';
    append_number(out, mesh.positions[i + 2]);
    out += '\n';
  }
  for (std::size_t i = 0; i < mesh.indices.size(); i += 3) {
    out += "3 ";
    append_uint(out, mesh.indices[i]);
    out += ' ';
    append_uint(out, mesh.indices[i + 1]);
    out += ' ';
    append_uint(out, mesh.indices[i + 2]);
    out += '\n';
  }
  return out;
}

}  // namespace qem::io
