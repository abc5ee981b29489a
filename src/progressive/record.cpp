// Building a Record from a simplify run's ContractionLog, and the invariants every Record obeys.
//
// The log speaks in input ids; the record renumbers to base ids (used vertices, initial faces)
// with order-preserving maps, so a record carries only the part of the input the run saw and
// still lists vertices and faces in input order, as build_output in src/core/working_mesh.cpp does.
#include <cmath>
#include <string>
#include <vector>

#include "qem/progressive.h"

namespace qem {

namespace {

constexpr std::uint32_t kNone = 0xffffffffu;

[[noreturn]] void fail(const std::string& name, const char* element, std::size_t i, const std::string& what) {
  throw Error(name + ", " + element + " " + std::to_string(i) + ": " + what);
}

}  // namespace

Record make_record(MeshView input, const ContractionLog& log) {
  const std::size_t nv = input.vertex_count(), nf = input.face_count();
  const std::size_t nc = log.size();
  if (log.removed.size() != nc || log.position.size() != 3 * nc || log.error.size() != nc ||
      log.dead_begin.size() != nc + 1 || log.dead_begin.back() != log.dead_faces.size())
    throw Error("contraction log: inconsistent array sizes");

  // Base faces: the initial faces, in input order.
  std::vector<std::uint32_t> face_id(nf, kNone);
  std::vector<std::uint32_t> vertex_id(nv, kNone);
  for (std::size_t j = 0; j < log.initial_faces.size(); ++j) {
    const std::uint32_t f = log.initial_faces[j];
    if (f >= nf || (j > 0 && f <= log.initial_faces[j - 1]))
      throw Error("contraction log: initial faces are not increasing input face ids");
    face_id[f] = std::uint32_t(j);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = input.indices[3 * std::size_t(f) + k];
      if (v >= nv)
        throw Error("contraction log: initial face " + std::to_string(f) + " has a vertex out of range");
      vertex_id[v] = 0;  // used; numbered below
    }
  }
  // Base vertices: the used ones, in input order.
  Record r;
  std::uint32_t next = 0;
  for (std::size_t v = 0; v < nv; ++v) {
    if (vertex_id[v] == kNone) continue;
    vertex_id[v] = next++;
    r.base.positions.insert(r.base.positions.end(), &input.positions[3 * v], &input.positions[3 * v] + 3);
  }
  r.base.indices.reserve(3 * log.initial_faces.size());
  for (std::uint32_t f : log.initial_faces)
    for (int k = 0; k < 3; ++k) r.base.indices.push_back(vertex_id[input.indices[3 * std::size_t(f) + k]]);

  auto vertex = [&](std::uint32_t v, std::size_t i) {
    if (v >= nv || vertex_id[v] == kNone)
      fail("contraction log", "contraction", i, "vertex not used by the run");
    return vertex_id[v];
  };
  r.kept.resize(nc);
  r.removed.resize(nc);
  for (std::size_t i = 0; i < nc; ++i) {
    r.kept[i] = vertex(log.kept[i], i);
    r.removed[i] = vertex(log.removed[i], i);
  }
  r.position = log.position;
  r.error = log.error;
  r.dead_begin = log.dead_begin;
  r.dead_faces.resize(log.dead_faces.size());
  for (std::size_t k = 0; k < log.dead_faces.size(); ++k) {
    const std::uint32_t f = log.dead_faces[k];
    if (f >= nf || face_id[f] == kNone) throw Error("contraction log: a dead face is not an initial face");
    r.dead_faces[k] = face_id[f];
  }
  validate_record(r, "contraction log");
  return r;
}

void validate_record(const Record& r, const std::string& name) {
  const std::size_t nv = r.base.vertex_count(), nf = r.base.face_count(), nc = r.size();
  if (r.base.positions.size() % 3 != 0 || r.base.indices.size() % 3 != 0)
    throw Error(name + ": base mesh arrays are not whole vertices / triangles");
  if (nv > kNone || nf > kNone) throw Error(name + ": too many vertices or faces for 32-bit ids");
  if (r.removed.size() != nc || r.position.size() != 3 * nc || r.error.size() != nc ||
      r.dead_begin.size() != nc + 1 || r.dead_begin.front() != 0 ||
      r.dead_begin.back() != r.dead_faces.size())
    throw Error(name + ": contraction arrays have inconsistent sizes");
  for (std::size_t i = 0; i < r.base.positions.size(); ++i)
    if (!std::isfinite(r.base.positions[i])) fail(name, "vertex", i / 3, "non-finite coordinate");
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t* t = &r.base.indices[3 * f];
    for (int k = 0; k < 3; ++k)
      if (t[k] >= nv)
        fail(name, "face", f, "refers to vertex " + std::to_string(t[k]) + " of " + std::to_string(nv));
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) fail(name, "face", f, "degenerate (a repeated corner)");
  }
  // Replay semantics: a removed vertex is gone for good, a face dies once.
  std::vector<std::uint8_t> gone(nv, 0), dead(nf, 0);
  for (std::size_t i = 0; i < nc; ++i) {
    const std::uint32_t a = r.kept[i], b = r.removed[i];
    if (a >= nv || b >= nv) fail(name, "contraction", i, "vertex id out of range");
    if (a == b) fail(name, "contraction", i, "keeps and removes the same vertex");
    if (gone[a] || gone[b]) fail(name, "contraction", i, "uses a vertex removed by an earlier contraction");
    gone[b] = 1;
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(r.position[3 * i + k])) fail(name, "contraction", i, "non-finite position");
    if (!(r.error[i] >= 0) || !std::isfinite(r.error[i]))
      fail(name, "contraction", i, "error is not finite and >= 0");
    if (r.dead_begin[i + 1] < r.dead_begin[i] || r.dead_begin[i + 1] > r.dead_faces.size())
      fail(name, "contraction", i, "dead face range out of order");
    for (std::uint32_t k = r.dead_begin[i]; k < r.dead_begin[i + 1]; ++k) {
      const std::uint32_t f = r.dead_faces[k];
      if (f >= nf) fail(name, "contraction", i, "dead face " + std::to_string(f) + " out of range");
      if (dead[f]) fail(name, "contraction", i, "face " + std::to_string(f) + " dies twice");
      dead[f] = 1;
    }
  }
}

}  // namespace qem
