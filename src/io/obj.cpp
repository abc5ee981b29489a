// Wavefront OBJ: `v x y z [w | r g b]` and `f` statements; every other statement (vt, vn, g, o, s,
// usemtl, mtllib, l, p, ...) is skipped. Indices may be negative (relative to the vertices read so
// far) and carry /vt/vn tails; polygons are fan-triangulated; `\` joins lines.
#include <string>
#include <vector>

#include "io/io_common.h"

namespace qem::io {

Mesh parse_obj(std::string_view bytes, const std::string& name, const LoadOptions&, LoadReport& report) {
  Mesh mesh;
  // Rough reservation from the file size (a vertex line is at least ~12 bytes); bounded by the data.
  mesh.positions.reserve(bytes.size() / 32 * 3);
  mesh.indices.reserve(bytes.size() / 32 * 3);
  PolygonSink sink{&mesh.indices};
  std::vector<std::uint32_t> corners;
  // Positive indices may refer to vertices defined later in the file, so they are range-checked at
  // the end; remember the largest one and where it was.
  long long max_positive = 0;
  std::size_t max_positive_line = 0;

  TextCursor in(bytes, name, '#', true);
  while (!in.at_end()) {
    in.skip_blank();
    if (in.at_line_end()) {
      in.next_line();
      continue;
    }
    std::string_view keyword = in.word();
    if (keyword == "v") {
      in.skip_blank();
      double x = in.number("an x coordinate");
      in.skip_blank();
      double y = in.number("a y coordinate");
      in.skip_blank();
      double z = in.number("a z coordinate");
      if (!finite3(x, y, z)) in.fail("vertex coordinate is not finite");
      mesh.positions.push_back(x);
      mesh.positions.push_back(y);
      mesh.positions.push_back(z);
      // Anything after xyz (w, or r g b colours) is ignored.
    } else if (keyword == "f") {
      corners.clear();
      const long long nv = static_cast<long long>(mesh.positions.size() / 3);
      for (;;) {
        in.skip_blank();
        if (in.at_line_end()) break;
        long long idx;
        if (!in.try_integer(idx, true)) in.fail_expected("a vertex index");
        in.skip_word();  // "/vt/vn"
        if (idx < 0) {
          idx += nv;  // relative: -1 is the last vertex read so far
          if (idx < 0)
            in.fail("relative vertex index " + std::to_string(idx - nv) + " refers before the first vertex");
        } else if (idx == 0) {
          in.fail("vertex index 0 (OBJ indices start at 1)");
        } else {
          if (idx > 0xFFFFFFFFLL) in.fail("vertex index " + std::to_string(idx) + " is too large");
          if (idx > max_positive) {
            max_positive = idx;
            max_positive_line = in.line();
          }
          --idx;
        }
        corners.push_back(static_cast<std::uint32_t>(idx));
      }
      if (corners.size() < 3)
        in.fail("face with " + std::to_string(corners.size()) + " vertices (at least 3 needed)");
      sink.add(corners.data(), corners.size());
    }
    in.next_line();
  }

  const std::size_t nv = mesh.vertex_count();
  if (static_cast<unsigned long long>(max_positive) > nv)
    fail_line(name, max_positive_line,
              "vertex index " + std::to_string(max_positive) + " out of range (file has " +
                  std::to_string(nv) + " vertices)");
  if (nv == 0) fail(name, "no vertices (not an OBJ mesh?)");
  if (mesh.indices.empty()) fail(name, "no faces");
  report.format = FileFormat::Obj;
  report.binary = false;
  report.polygons_triangulated = sink.polygons;
  // No shrink_to_fit: the unused reserve was never touched (costs no memory pages), whereas
  // shrinking would copy both arrays.
  return mesh;
}

std::string write_obj(const Mesh& mesh) {
  std::string out;
  out.reserve(mesh.positions.size() * 12 + mesh.indices.size() * 8 + 64);
  out += "# written by qem\n";
  for (std::size_t i = 0; i < mesh.positions.size(); i += 3) {
    out += "v ";
    append_number(out, mesh.positions[i]);
    out += ' ';
    append_number(out, mesh.positions[i + 1]);
    out += ' ';
    append_number(out, mesh.positions[i + 2]);
    out += '\n';
  }
  for (std::size_t i = 0; i < mesh.indices.size(); i += 3) {
    out += "f ";
    append_uint(out, std::uint64_t{mesh.indices[i]} + 1);
    out += ' ';
    append_uint(out, std::uint64_t{mesh.indices[i + 1]} + 1);
    out += ' ';
    append_uint(out, std::uint64_t{mesh.indices[i + 2]} + 1);
    out += '\n';
  }
  return out;
}

}  // namespace qem::io
