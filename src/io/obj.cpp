// Wavefront OBJ: `v x y z [w | r g b]`, `vt`, `vn`, `f` with v/vt/vn corners, `usemtl` and
// `mtllib`; every other statement (vp, g, o, s, l, p, ...) is skipped. Indices may be negative
// (relative to the elements read so far); polygons are fan-triangulated; `\` joins lines.
//
// Attributes (docs/attributes.md). OBJ indexes positions, texture coordinates and normals
// separately per face corner; qem's vertices are wedges (one set of values each), so when faces
// index `vt` or `vn` every distinct (v, vt, vn) triple used by a corner becomes one vertex, its
// position duplicated. Vertices stay in `v` order: the wedges of one `v` line are consecutive, in
// the order faces first use them, and a `v` line no face uses stays one (unreferenced) vertex.
// A corner without a `vt` (or `vn`) in a file whose other corners have one gets the value 0, as
// assimp does (trimesh refuses such faces; files that texture only some parts are common enough
// that refusing them would be worse). The writer welds: wedges that share a position (and colour)
// share a `v` line, equal texture coordinates and normals share `vt`/`vn` lines.
#include <array>
#include <bit>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

#include "io/io_common.h"

namespace qem::io {

namespace {

constexpr std::uint32_t kNone = 0xFFFFFFFFu;

/// An index read from a face corner, resolved to 0-based; positive ones are range-checked at the
/// end because they may refer to elements defined later in the file.
struct IndexCheck {
  const char* what;  // "vertex", "texture coordinate", "normal"
  long long max_positive = 0;
  std::size_t line = 0;

  /// Resolves a 1-based or negative OBJ index against `count` elements read so far.
  std::uint32_t resolve(long long idx, std::size_t count, TextCursor& in) {
    const long long n = static_cast<long long>(count);
    if (idx < 0) {
      idx += n;  // relative: -1 is the last element read so far
      if (idx < 0)
        in.fail(std::string("relative ") + what + " index " + std::to_string(idx - n) +
                " refers before the first " + what);
      return static_cast<std::uint32_t>(idx);
    }
    if (idx == 0) in.fail(std::string(what) + " index 0 (OBJ indices start at 1)");
    if (idx > 0xFFFFFFFELL) in.fail(std::string(what) + " index " + std::to_string(idx) + " is too large");
    if (idx > max_positive) {
      max_positive = idx;
      line = in.line();
    }
    return static_cast<std::uint32_t>(idx - 1);
  }
  void check(const std::string& name, std::size_t count, const char* plural) const {
    if (static_cast<unsigned long long>(max_positive) > count)
      fail_line(name, line,
                std::string(what) + " index " + std::to_string(max_positive) + " out of range (file has " +
                    std::to_string(count) + " " + plural + ")");
  }
};

/// Per triangle corner `vt` / `vn` indices, started lazily at the first corner that has one (the
/// corners before it get kNone), so files without them pay nothing.
struct CornerColumn {
  std::vector<std::uint32_t> values;
  bool used = false;
  void push(std::uint32_t v, std::size_t corners_before) {
    if (!used && v == kNone) return;
    if (!used) {
      used = true;
      values.assign(corners_before, kNone);
    }
    values.push_back(v);
  }
};

/// Builds the wedges: one vertex per distinct (v, vt, vn) triple used by a corner, plus one per
/// unused `v` line. Rewrites mesh.indices and fills the attributes.
void build_wedges(Mesh& mesh, const CornerColumn& tex, const CornerColumn& nrm, const std::vector<double>& uv,
                  const std::vector<double>& normals, std::vector<double>* colours) {
  const std::size_t np = mesh.vertex_count(), nc = mesh.indices.size();
  auto vt_of = [&](std::size_t c) { return tex.used ? tex.values[c] : kNone; };
  auto vn_of = [&](std::size_t c) { return nrm.used ? nrm.values[c] : kNone; };
  // Wedges of each position as a chain in first-use order: head/tail per position, next per wedge.
  std::vector<std::uint32_t> head(np, kNone), tail(np, kNone);
  std::vector<std::uint32_t> next, wedge_vt, wedge_vn;
  std::vector<std::uint32_t> corner_wedge(nc);
  for (std::size_t c = 0; c < nc; ++c) {
    const std::uint32_t p = mesh.indices[c], t = vt_of(c), n = vn_of(c);
    std::uint32_t w = head[p];
    // Positions rarely have more than a few wedges, so a walk beats a hash table.
    while (w != kNone && (wedge_vt[w] != t || wedge_vn[w] != n)) w = next[w];
    if (w == kNone) {
      w = static_cast<std::uint32_t>(next.size());
      next.push_back(kNone);
      wedge_vt.push_back(t);
      wedge_vn.push_back(n);
      if (head[p] == kNone)
        head[p] = w;
      else
        next[tail[p]] = w;
      tail[p] = w;
    }
    corner_wedge[c] = w;
  }
  // Final numbering: positions in file order, each position's wedges consecutive.
  std::vector<std::uint32_t> wedge_id(next.size());
  std::vector<double> positions;
  positions.reserve(3 * (next.size() + np));
  std::vector<std::uint32_t> source;  // new vertex -> its position (v line)
  std::vector<std::uint32_t> source_wedge;
  source.reserve(next.size() + np);
  for (std::uint32_t p = 0; p < np; ++p) {
    if (head[p] == kNone) {
      source.push_back(p);
      source_wedge.push_back(kNone);
      continue;
    }
    for (std::uint32_t w = head[p]; w != kNone; w = next[w]) {
      wedge_id[w] = static_cast<std::uint32_t>(source.size());
      source.push_back(p);
      source_wedge.push_back(w);
    }
  }
  const std::size_t nv = source.size();
  positions.resize(3 * nv);
  for (std::size_t v = 0; v < nv; ++v)
    std::memcpy(&positions[3 * v], &mesh.positions[3 * std::size_t{source[v]}], 3 * sizeof(double));
  if (tex.used) {
    VertexAttribute a{"TEXCOORD_0", AttributeKind::TexCoord, 2, std::vector<double>(2 * nv, 0.0)};
    for (std::size_t v = 0; v < nv; ++v) {
      const std::uint32_t w = source_wedge[v];
      if (w == kNone || wedge_vt[w] == kNone) continue;  // unused v line or corner without vt: 0
      a.values[2 * v] = uv[2 * std::size_t{wedge_vt[w]}];
      a.values[2 * v + 1] = uv[2 * std::size_t{wedge_vt[w]} + 1];
    }
    mesh.attributes.push_back(std::move(a));
  }
  if (nrm.used) {
    VertexAttribute a{"NORMAL", AttributeKind::Normal, 3, std::vector<double>(3 * nv, 0.0)};
    for (std::size_t v = 0; v < nv; ++v) {
      const std::uint32_t w = source_wedge[v];
      if (w == kNone || wedge_vn[w] == kNone) continue;
      std::memcpy(&a.values[3 * v], &normals[3 * std::size_t{wedge_vn[w]}], 3 * sizeof(double));
    }
    mesh.attributes.push_back(std::move(a));
  }
  if (colours) {
    std::vector<double> c(3 * nv);
    for (std::size_t v = 0; v < nv; ++v)
      std::memcpy(&c[3 * v], &(*colours)[3 * std::size_t{source[v]}], 3 * sizeof(double));
    colours->swap(c);
  }
  for (std::size_t c = 0; c < nc; ++c) mesh.indices[c] = wedge_id[corner_wedge[c]];
  mesh.positions.swap(positions);
}

}  // namespace

Mesh parse_obj(std::string_view bytes, const std::string& name, const LoadOptions& options,
               LoadReport& report) {
  const bool attributes = options.read_attributes;
  Mesh mesh;
  // Rough reservation from the file size (a vertex line is at least ~12 bytes); bounded by the data.
  mesh.positions.reserve(bytes.size() / 32 * 3);
  mesh.indices.reserve(bytes.size() / 32 * 3);
  PolygonSink sink{&mesh.indices};
  std::vector<std::uint32_t> corners, corner_vt, corner_vn;
  IndexCheck v_check{"vertex"}, vt_check{"texture coordinate"}, vn_check{"normal"};
  std::vector<double> uv, normals, colours;  // colours: 3 per v line, filled from the first coloured one
  bool coloured = false;
  CornerColumn tex, nrm;
  std::unordered_map<std::string, std::uint32_t> material_index;
  std::string material;  // the current `usemtl` name
  bool any_usemtl = false;
  std::uint32_t current_material = kNone;  // its index, once a face has used it

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
      if (attributes) {
        // `v x y z r g b` (MeshLab, trimesh, ZBrush-style exports) carries a colour; `v x y z w` a
        // weight we ignore; anything else after xyz is ignored as before.
        double rgb[3];
        int extra = 0;
        for (; extra < 3; ++extra) {
          in.skip_blank();
          if (in.at_line_end() || !in.try_number(rgb[extra])) break;
        }
        if (extra == 3) {
          if (!finite3(rgb[0], rgb[1], rgb[2])) in.fail("vertex colour is not finite");
          if (!coloured) {
            // Vertices before the first coloured one are white, the colour a renderer assumes.
            coloured = true;
            colours.assign(mesh.positions.size() - 3, 1.0);
          }
          colours.insert(colours.end(), rgb, rgb + 3);
        } else if (coloured) {
          colours.insert(colours.end(), {1.0, 1.0, 1.0});
        }
      }
    } else if (keyword == "vt" && attributes) {
      in.skip_blank();
      double u = in.number("a u texture coordinate");
      double v = 0;  // `vt u` is a 1D texture: v defaults to 0 (OBJ specification)
      in.skip_blank();
      if (!in.at_line_end()) v = in.number("a v texture coordinate");
      // A third value (w, 3D textures) is ignored.
      if (!std::isfinite(u) || !std::isfinite(v)) in.fail("texture coordinate is not finite");
      uv.push_back(u);
      uv.push_back(v);
    } else if (keyword == "vn" && attributes) {
      in.skip_blank();
      double x = in.number("a normal x");
      in.skip_blank();
      double y = in.number("a normal y");
      in.skip_blank();
      double z = in.number("a normal z");
      if (!finite3(x, y, z)) in.fail("normal is not finite");
      normals.insert(normals.end(), {x, y, z});
    } else if (keyword == "f") {
      corners.clear();
      corner_vt.clear();
      corner_vn.clear();
      const std::size_t np = mesh.positions.size() / 3;
      for (;;) {
        in.skip_blank();
        if (in.at_line_end()) break;
        long long idx;
        if (!in.try_integer(idx, true)) in.fail_expected("a vertex index");
        corners.push_back(v_check.resolve(idx, np, in));
        std::uint32_t t = kNone, n = kNone;
        if (!attributes) {
          in.skip_word();  // "/vt/vn"
        } else if (in.skip_char('/')) {
          // v/vt, v/vt/vn or v//vn; an empty field means none.
          auto field = [&in] { return !in.at_line_end() && !in.is_delim(*in.pos()); };
          bool has_vn = in.skip_char('/');
          if (!has_vn) {
            long long k;
            if (field()) {
              if (!in.try_integer(k, true)) in.fail_expected("a texture coordinate index");
              t = vt_check.resolve(k, uv.size() / 2, in);
            }
            has_vn = in.skip_char('/');
          }
          long long k;
          if (has_vn && field()) {
            if (!in.try_integer(k, false)) in.fail_expected("a normal index");
            n = vn_check.resolve(k, normals.size() / 3, in);
          }
        }
        if (!in.at_line_end() && !in.is_delim(*in.pos())) in.fail_expected("a vertex index");
        corner_vt.push_back(t);
        corner_vn.push_back(n);
      }
      if (corners.size() < 3)
        in.fail("face with " + std::to_string(corners.size()) + " vertices (at least 3 needed)");
      const std::size_t before = mesh.indices.size();
      sink.add(corners.data(), corners.size());
      if (attributes) {
        // The same fan as PolygonSink: triangle k - 2 has corners 0, k - 1, k.
        std::size_t c = before;
        for (std::size_t k = 2; k < corners.size(); ++k)
          for (std::size_t j : {std::size_t{0}, k - 1, k}) {
            tex.push(corner_vt[j], c);
            nrm.push(corner_vn[j], c);
            ++c;
          }
        if (any_usemtl) {
          if (current_material == kNone) {  // the first face since a usemtl: look its name up once
            auto [it, added] =
                material_index.try_emplace(material, static_cast<std::uint32_t>(mesh.material_names.size()));
            if (added) mesh.material_names.push_back(material);
            current_material = it->second;
          }
          mesh.face_materials.insert(mesh.face_materials.end(), corners.size() - 2, current_material);
        }
      }
    } else if (keyword == "usemtl" && attributes) {
      if (!any_usemtl) {
        any_usemtl = true;
        // Faces before the first usemtl have no material: they get the unnamed one.
        if (!mesh.indices.empty()) {
          material_index.emplace("", 0);
          mesh.material_names.push_back("");
          mesh.face_materials.assign(mesh.indices.size() / 3, 0);
        }
      }
      material = std::string(in.rest_of_line());
      current_material = kNone;
    } else if (keyword == "mtllib" && attributes) {
      std::string library(in.rest_of_line());
      if (mesh.material_library.empty())
        mesh.material_library = library;
      else if (library != mesh.material_library)
        report.warnings.push_back(
            at_line(name, in.line(),
                    "second mtllib '" + library.substr(0, 64) + "' ignored (one material library is kept)"));
    }
    in.next_line();
  }

  const std::size_t np = mesh.vertex_count();
  v_check.check(name, np, "vertices");
  vt_check.check(name, uv.size() / 2, "texture coordinates");
  vn_check.check(name, normals.size() / 3, "normals");
  if (np == 0) fail(name, "no vertices (not an OBJ mesh?)");
  if (mesh.indices.empty()) fail(name, "no faces");
  if (tex.used || nrm.used) {
    if (mesh.indices.size() >= kNone) fail(name, "too many face corners for 32-bit indices");
    build_wedges(mesh, tex, nrm, uv, normals, coloured ? &colours : nullptr);
  }
  if (coloured) mesh.attributes.push_back({"COLOR_0", AttributeKind::Color, 3, std::move(colours)});
  if (mesh.material_names.size() == 1 && mesh.material_names[0].empty()) {
    // Only faces before a trailing usemtl: no face has a material.
    mesh.material_names.clear();
    mesh.face_materials.clear();
  }
  report.format = FileFormat::Obj;
  report.binary = false;
  report.polygons_triangulated = sink.polygons;
  // No shrink_to_fit: the unused reserve was never touched (costs no memory pages), whereas
  // shrinking would copy both arrays.
  return mesh;
}

// --- writer --------------------------------------------------------------------------------------

namespace {

/// Values compared bit for bit (with -0 folded onto +0, as when welding positions).
template <std::size_t N>
struct BitsHash {
  std::size_t operator()(const std::array<std::uint64_t, N>& k) const {
    std::uint64_t h = 0x9E3779B97F4A7C15ull;
    for (std::uint64_t x : k) h = (h ^ x) * 0xC2B2AE3D27D4EB4Full, h ^= h >> 29;
    return static_cast<std::size_t>(h);
  }
};
inline std::uint64_t bits(double v) { return std::bit_cast<std::uint64_t>(v == 0.0 ? 0.0 : v); }

/// Numbers the distinct N-tuples of `values` (stride `stride`, the first N used, missing ones 0) in
/// first-occurrence order; `id[v]` gets each vertex's number, `unique` the tuples.
template <std::size_t N>
void number_values(const VertexAttribute& a, std::size_t nv, std::vector<std::uint32_t>& id,
                   std::vector<double>& unique) {
  std::unordered_map<std::array<std::uint64_t, N>, std::uint32_t, BitsHash<N>> seen;
  seen.reserve(nv);
  id.resize(nv);
  for (std::size_t v = 0; v < nv; ++v) {
    std::array<double, N> x{};
    for (std::size_t k = 0; k < N && k < a.components; ++k) x[k] = a.values[a.components * v + k];
    std::array<std::uint64_t, N> key;
    for (std::size_t k = 0; k < N; ++k) key[k] = bits(x[k]);
    auto [it, added] = seen.try_emplace(key, static_cast<std::uint32_t>(unique.size() / N));
    if (added) unique.insert(unique.end(), x.begin(), x.end());
    id[v] = it->second;
  }
}

/// A name as one OBJ statement argument: control characters and '#' (a comment to readers) become
/// '_' (names from other formats may hold anything).
std::string one_line(std::string s) {
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 32 || c == '#' || c == '\\') c = '_';
  return s;
}

void append_values(std::string& out, const char* keyword, const double* x, std::size_t n) {
  out += keyword;
  for (std::size_t k = 0; k < n; ++k) {
    out += ' ';
    append_number(out, x[k]);
  }
  out += '\n';
}

}  // namespace

std::string write_obj(const Mesh& mesh) {
  const std::size_t nv = mesh.vertex_count(), nf = mesh.face_count();
  // OBJ holds one set each of texture coordinates, normals and (v-line) colours: the first
  // attribute of each kind; the others are not written.
  const VertexAttribute* tex = mesh.find_attribute(AttributeKind::TexCoord);
  const VertexAttribute* nrm = mesh.find_attribute(AttributeKind::Normal);
  const VertexAttribute* col = mesh.find_attribute(AttributeKind::Color);
  std::string out;
  out.reserve(mesh.positions.size() * 12 + mesh.indices.size() * 8 + 64);
  out += "# written by qem\n";
  if (!mesh.material_library.empty()) out += "mtllib " + one_line(mesh.material_library) + "\n";

  // v line of each vertex. Without vt/vn, one per vertex (as read). With them, wedges that share a
  // position and colour share a line; a vertex whose (v, vt, vn) would repeat an earlier vertex's
  // gets its own line, so every vertex reads back as itself; unused vertices get their own line, or
  // the faces of the vertex sharing it would make it used.
  std::vector<std::uint32_t> vline(nv), vt_id, vn_id;
  std::vector<double> vt_values, vn_values;
  const bool wedges = tex || nrm;
  if (tex) number_values<2>(*tex, nv, vt_id, vt_values);
  if (nrm) number_values<3>(*nrm, nv, vn_id, vn_values);
  std::uint32_t lines = 0;
  if (!wedges) {
    for (std::size_t v = 0; v < nv; ++v) vline[v] = lines++;
  } else {
    std::vector<std::uint8_t> used(nv, 0);
    for (std::uint32_t i : mesh.indices) used[i] = 1;
    std::unordered_map<std::array<std::uint64_t, 6>, std::uint32_t, BitsHash<6>> line_of;
    std::unordered_map<std::array<std::uint64_t, 3>, std::uint8_t, BitsHash<3>> triples;
    line_of.reserve(nv);
    triples.reserve(nv);
    for (std::size_t v = 0; v < nv; ++v) {
      if (!used[v]) {
        vline[v] = lines++;
        continue;
      }
      std::array<std::uint64_t, 6> key{bits(mesh.positions[3 * v]),
                                       bits(mesh.positions[3 * v + 1]),
                                       bits(mesh.positions[3 * v + 2]),
                                       0,
                                       0,
                                       0};
      if (col)
        for (std::size_t k = 0; k < 3 && k < col->components; ++k)
          key[3 + k] = bits(col->values[col->components * v + k]);
      auto [it, added] = line_of.try_emplace(key, lines);
      std::uint32_t line = it->second;
      const std::uint64_t t = tex ? vt_id[v] : 0, n = nrm ? vn_id[v] : 0;
      if (!added && !triples.try_emplace({line, t, n}, 0).second) {
        line = lines;  // a duplicate vertex: a line of its own (not reused by later vertices)
        triples.try_emplace({line, t, n}, 0);
      } else if (added) {
        triples.try_emplace({line, t, n}, 0);
      }
      if (line == lines) ++lines;
      vline[v] = line;
    }
  }
  // The v lines in order: the first vertex of each line gives its values.
  std::vector<std::uint32_t> first(lines, kNone);
  for (std::size_t v = 0; v < nv; ++v)
    if (first[vline[v]] == kNone) first[vline[v]] = static_cast<std::uint32_t>(v);
  for (std::uint32_t line = 0; line < lines; ++line) {
    const std::size_t v = first[line];
    out += "v ";
    append_number(out, mesh.positions[3 * v]);
    out += ' ';
    append_number(out, mesh.positions[3 * v + 1]);
    out += ' ';
    append_number(out, mesh.positions[3 * v + 2]);
    if (col)
      for (std::size_t k = 0; k < 3; ++k) {
        out += ' ';
        append_number(out, k < col->components ? col->values[col->components * v + k] : 0.0);
      }
    out += '\n';
  }
  for (std::size_t i = 0; i < vt_values.size(); i += 2) append_values(out, "vt", &vt_values[i], 2);
  for (std::size_t i = 0; i < vn_values.size(); i += 3) append_values(out, "vn", &vn_values[i], 3);

  const bool materials = !mesh.face_materials.empty();
  auto usemtl = [&](std::uint32_t m) {
    // An unnamed material is written as a bare `usemtl`, which reads back as the unnamed one; an
    // index without a name gets one, so faces of different materials stay apart.
    std::string n = m < mesh.material_names.size() ? mesh.material_names[m] : "material_" + std::to_string(m);
    out += "usemtl";
    if (!n.empty()) out += ' ' + one_line(n);
    out += '\n';
  };
  std::uint32_t current = materials ? mesh.face_materials[0] : 0;
  // Leading faces of the unnamed material are the faces before any usemtl: no statement needed.
  if (materials && !(current < mesh.material_names.size() && mesh.material_names[current].empty()))
    usemtl(current);
  for (std::size_t f = 0; f < nf; ++f) {
    if (materials && mesh.face_materials[f] != current) {
      current = mesh.face_materials[f];
      usemtl(current);
    }
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = mesh.indices[3 * f + k];
      out += ' ';
      append_uint(out, std::uint64_t{vline[v]} + 1);
      if (!wedges) continue;
      out += '/';
      if (tex) append_uint(out, std::uint64_t{vt_id[v]} + 1);
      if (nrm) {
        out += '/';
        append_uint(out, std::uint64_t{vn_id[v]} + 1);
      }
    }
    out += '\n';
  }
  return out;
}

}  // namespace qem::io
