#include "outofcore/mesh_generator.h"

#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <unordered_map>
#include <vector>

#include "outofcore/temp_file.h"
#include "qem/error.h"

namespace qem::outofcore {
namespace {

const double kGolden = (1.0 + std::sqrt(5.0)) / 2.0;
const double kIcosahedron[36] = {-1, kGolden, 0, 1, kGolden,  0, -1, -kGolden, 0, 1, -kGolden, 0,       0,
                                 -1, kGolden, 0, 1, kGolden,  0, -1, -kGolden, 0, 1, -kGolden, kGolden, 0,
                                 -1, kGolden, 0, 1, -kGolden, 0, -1, -kGolden, 0, 1};
const std::uint32_t kIcosahedronFaces[60] = {
    0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,  11, 10, 2,  10, 7, 6, 7, 1, 8,
    3, 9,  4, 3, 4, 2, 3, 2, 6, 3, 6, 8,  3, 8,  9,  4, 9, 5, 2, 4,  11, 6,  2,  10, 8,  6, 7, 9, 8, 1};

/// Subdivision levels of the sphere with at least `faces` faces.
int sphere_levels(std::uint64_t faces) {
  int levels = 0;
  while ((20ull << (2 * levels)) < faces) ++levels;
  return levels;
}

/// Projects an icosphere vertex to the unit sphere and displaces it by the waves: one function for
/// both generators, so they compute the same bits.
void displace(const double in[3], double out[3]) {
  double len = std::sqrt(in[0] * in[0] + in[1] * in[1] + in[2] * in[2]);
  double x = in[0] / len, y = in[1] / len, z = in[2] / len;
  double r = 1 + 0.08 * std::sin(7 * x + 1) * std::sin(6 * y) + 0.04 * std::cos(13 * z + 2 * x) +
             0.02 * std::sin(23 * y + 17 * z);
  out[0] = x * r, out[1] = y * r, out[2] = z * r;
}

std::size_t torus_ring(std::uint64_t faces) {
  std::size_t n = 8;
  while (std::uint64_t(n) * (n / 2) * 2 < faces) n += 2;
  return n;
}

void torus_point(std::size_t i, std::size_t j, std::size_t n, std::size_t m_ring, double out[3]) {
  double u = 2 * M_PI * double(i) / double(n), v = 2 * M_PI * double(j) / double(m_ring);
  double r = 1 + 0.35 * std::cos(v);
  out[0] = r * std::cos(u), out[1] = r * std::sin(u), out[2] = 0.35 * std::sin(v);
}

// --- the streamed binary PLY ------------------------------------------------------------------------

/// The header write_ply gives a positions-only mesh in binary with float values.
void write_header(BufferedWriter& out, std::uint64_t vertices, std::uint64_t faces) {
  std::string h = "ply\nformat binary_little_endian 1.0\ncomment written by qem\nelement vertex " +
                  std::to_string(vertices) +
                  "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                  std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
  out.write(h.data(), h.size());
}

void write_vertex(BufferedWriter& out, const double p[3]) {
  const float f[3] = {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])};
  out.write(f, sizeof f);
}

void write_face(BufferedWriter& out, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  char row[13];
  row[0] = 3;
  const std::int32_t v[3] = {std::int32_t(a), std::int32_t(b), std::int32_t(c)};
  std::memcpy(row + 1, v, 12);
  out.write(row, sizeof row);
}

/// The icosphere's subdivision replayed depth first. bumpy_sphere subdivides level by level, and
/// numbers each edge's midpoint when the first of its two faces is visited in face order; the
/// faces of each level keep their parents' order (4 children each). Visiting the hierarchy depth
/// first meets the faces of every level in that same order, so a per-level table of edges seen
/// once gives every midpoint the same number, and it can forget an edge at its second face (the
/// sphere is closed: two faces an edge). Only the edges between the visited and the unvisited
/// part are held: a few rows per base face.
class SphereWalk {
 public:
  struct Corner {
    std::uint32_t id;
    double p[3];
  };

  /// Walks to `depth` levels; with `emit_vertices`, writes the vertices created at level `depth`
  /// (in number order); else writes the faces of level `depth`.
  SphereWalk(int depth, bool emit_vertices, BufferedWriter& out)
      : depth_(depth), emit_vertices_(emit_vertices), out_(out), pending_(depth + 1), next_(depth + 1) {
    for (int l = 1; l <= depth; ++l) next_[l] = std::uint32_t(10ull * (1ull << (2 * (l - 1))) + 2);
  }

  void run() {
    if (emit_vertices_ && depth_ == 0) {
      for (int v = 0; v < 12; ++v) emit_vertex(kIcosahedron + 3 * v);
      return;
    }
    for (int f = 0; f < 20; ++f) {
      Corner c[3];
      for (int k = 0; k < 3; ++k) {
        c[k].id = kIcosahedronFaces[3 * f + k];
        std::copy(kIcosahedron + 3 * c[k].id, kIcosahedron + 3 * c[k].id + 3, c[k].p);
      }
      visit(0, c[0], c[1], c[2]);
    }
  }

 private:
  void emit_vertex(const double p[3]) {
    double d[3];
    displace(p, d);
    write_vertex(out_, d);
  }

  Corner midpoint(int level, const Corner& a, const Corner& b) {
    Corner m;
    for (int k = 0; k < 3; ++k) m.p[k] = (a.p[k] + b.p[k]) / 2;  // as bumpy_sphere (a + b == b + a)
    const std::uint64_t key =
        a.id < b.id ? (std::uint64_t(a.id) << 32 | b.id) : (std::uint64_t(b.id) << 32 | a.id);
    auto& table = pending_[level];
    if (auto it = table.find(key); it != table.end()) {
      m.id = it->second;
      table.erase(it);
    } else {
      m.id = next_[level]++;
      table.emplace(key, m.id);
      if (emit_vertices_ && level == depth_) emit_vertex(m.p);
    }
    return m;
  }

  void visit(int level, const Corner& a, const Corner& b, const Corner& c) {
    if (level == depth_) {
      if (!emit_vertices_) write_face(out_, a.id, b.id, c.id);
      return;
    }
    const Corner ab = midpoint(level + 1, a, b), bc = midpoint(level + 1, b, c),
                 ca = midpoint(level + 1, c, a);
    visit(level + 1, a, ab, ca);
    visit(level + 1, b, bc, ab);
    visit(level + 1, c, ca, bc);
    visit(level + 1, ab, bc, ca);
  }

  int depth_;
  bool emit_vertices_;
  BufferedWriter& out_;
  std::vector<std::unordered_map<std::uint64_t, std::uint32_t>> pending_;
  std::vector<std::uint32_t> next_;
};

}  // namespace

Mesh bumpy_sphere(std::size_t faces) {
  Mesh m;
  m.positions.assign(kIcosahedron, kIcosahedron + 36);
  m.indices.assign(kIcosahedronFaces, kIcosahedronFaces + 60);
  while (m.face_count() < faces) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      auto key = a < b ? std::make_pair(a, b) : std::make_pair(b, a);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      auto v = std::uint32_t(m.vertex_count());
      for (int k = 0; k < 3; ++k)
        m.positions.push_back((m.positions[3 * a + k] + m.positions[3 * b + k]) / 2);
      mid.emplace(key, v);
      return v;
    };
    std::vector<std::uint32_t> next;
    next.reserve(4 * m.indices.size());
    for (std::size_t f = 0; f < m.indices.size(); f += 3) {
      std::uint32_t a = m.indices[f], b = m.indices[f + 1], c = m.indices[f + 2];
      std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    m.indices.swap(next);
  }
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    double* p = &m.positions[3 * v];
    double d[3];
    displace(p, d);
    std::copy(d, d + 3, p);
  }
  return m;
}

Mesh torus(std::size_t faces) {
  const std::size_t n = torus_ring(faces), m_ring = n / 2;
  Mesh m;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m_ring; ++j) {
      double p[3];
      torus_point(i, j, n, m_ring, p);
      m.positions.insert(m.positions.end(), p, p + 3);
    }
  auto id = [&](std::size_t i, std::size_t j) { return std::uint32_t((i % n) * m_ring + (j % m_ring)); };
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m_ring; ++j) {
      m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

GeneratedCounts bumpy_sphere_counts(std::uint64_t faces) {
  const int l = sphere_levels(faces);
  return {10ull * (1ull << (2 * l)) + 2, 20ull << (2 * l)};
}

GeneratedCounts torus_counts(std::uint64_t faces) {
  const std::uint64_t n = torus_ring(faces);
  return {n * (n / 2), n * (n / 2) * 2};
}

GeneratedCounts write_bumpy_sphere_ply(const std::string& path, std::uint64_t faces) {
  if (faces > kMaxStreamedSphereFaces)
    throw Error("--faces is too large for a sphere (at most " + std::to_string(kMaxStreamedSphereFaces) +
                ")");
  const int levels = sphere_levels(faces);
  const GeneratedCounts counts = bumpy_sphere_counts(faces);
  AtomicOutput out(path);
  write_header(out, counts.vertices, counts.faces);
  // Vertices are numbered level by level, so each level's new vertices come from one walk to that
  // level: 4/3 of a full walk in all, for a file that lists vertices before faces.
  for (int l = 0; l <= levels; ++l) SphereWalk(l, true, out).run();
  SphereWalk(levels, false, out).run();
  out.commit();
  return counts;
}

GeneratedCounts write_torus_ply(const std::string& path, std::uint64_t faces) {
  if (faces > kMaxStreamedTorusFaces)
    throw Error("--faces is too large for a torus (at most " + std::to_string(kMaxStreamedTorusFaces) + ")");
  const std::size_t n = torus_ring(faces), m_ring = n / 2;
  const GeneratedCounts counts = torus_counts(faces);
  AtomicOutput out(path);
  write_header(out, counts.vertices, counts.faces);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m_ring; ++j) {
      double p[3];
      torus_point(i, j, n, m_ring, p);
      write_vertex(out, p);
    }
  auto id = [&](std::size_t i, std::size_t j) { return std::uint32_t((i % n) * m_ring + (j % m_ring)); };
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m_ring; ++j) {
      write_face(out, id(i, j), id(i + 1, j), id(i + 1, j + 1));
      write_face(out, id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  out.commit();
  return counts;
}

}  // namespace qem::outofcore
