#include "core/working_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>

#include "check_mesh.h"
#include "core/same_position.h"
#include "core/small_sort.h"
#include "core/spatial_order.h"
#include "qem/error.h"

namespace qem::core {

namespace {

bool degenerate(const std::uint32_t* t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

// The referenced vertices (those of a face that is not degenerate: a degenerate face carries no
// plane and no area), in input order. Unreferenced ones take no part and leave the output.
std::vector<std::uint32_t> referenced_vertices(MeshView in, std::size_t& degenerate_faces) {
  std::vector<std::uint8_t> referenced(in.vertex_count(), 0);
  for (std::size_t f = 0; f < in.face_count(); ++f) {
    const std::uint32_t* t = &in.indices[3 * f];
    if (degenerate(t)) {
      ++degenerate_faces;
      continue;
    }
    referenced[t[0]] = referenced[t[1]] = referenced[t[2]] = 1;
  }
  std::vector<std::uint32_t> used;
  used.reserve(referenced.size());  // no reallocation copies (valid_pairs.cpp, unique_edges)
  for (std::uint32_t v = 0; v < referenced.size(); ++v)
    if (referenced[v]) used.push_back(v);
  return used;
}

// The frame: centre and diagonal of the referenced vertices' bounding box.
void set_frame(MeshView in, const std::vector<std::uint32_t>& used, WorkingMesh& m) {
  if (used.empty()) return;
  const Box box = box_of_points(in.positions, used);
  // Beyond 1e300 the quadrics (squared distances times areas) overflow double precision.
  for (int k = 0; k < 3; ++k)
    if (!(std::fabs(box.lo[k]) <= 1e300 && std::fabs(box.hi[k]) <= 1e300))
      throw Error("coordinates beyond 1e300 in magnitude cannot be simplified in double precision");
  m.frame = frame_of_box(box);
}

// Working vertices numbered along a Morton curve (memory locality, spatial_order.h); returns each
// input vertex's working index.
std::vector<std::uint32_t> number_vertices(MeshView in, std::vector<std::uint32_t> used, WorkingMesh& m) {
  auto normalized = [&](std::uint32_t v) {
    return m.frame.to_frame_by_reciprocal(Vec3(in.positions[3 * v], in.positions[3 * v + 1], in.positions[3 * v + 2]));
  };
  m.source_vertex = morton_order(used.size(), [&](std::size_t i) { return normalized(used[i]); });
  for (std::uint32_t& v : m.source_vertex) v = used[v];
  std::vector<std::uint32_t>().swap(used);
  const std::uint32_t n = std::uint32_t(m.source_vertex.size());
  std::vector<std::uint32_t> internal(in.vertex_count(), 0);
  m.pos.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    internal[m.source_vertex[i]] = i;
    m.pos[i] = normalized(m.source_vertex[i]);
  }
  return internal;
}

// Faces bucketed by their lowest working vertex (a counting sort: neighbouring faces end up
// together in memory). Duplicates (same three vertices, either orientation) share a bucket: they
// would count their plane twice and survive as duplicates in the output, so only the first in
// input order is kept.
void add_faces(MeshView in, const std::vector<std::uint32_t>& internal, bool welded, WorkingMesh& m) {
  const std::size_t nf = in.face_count(), n = m.pos.size();
  auto sorted_corners = [&](std::size_t f) {
    std::uint32_t x = internal[in.indices[3 * f]], y = internal[in.indices[3 * f + 1]],
                  z = internal[in.indices[3 * f + 2]];
    if (x > y) std::swap(x, y);  // three compare-exchanges sort three
    if (y > z) std::swap(y, z);
    if (x > y) std::swap(x, y);
    return std::array<std::uint32_t, 3>{x, y, z};
  };
  // On working vertices: with attributes, two corners of different input vertices may share a
  // position (welded), and the face is degenerate too.
  auto collapsed = [&](std::size_t f) {
    if (!welded) return degenerate(&in.indices[3 * f]);
    const std::array<std::uint32_t, 3> t = sorted_corners(f);
    return t[0] == t[1] || t[1] == t[2];
  };
  if (welded)
    for (std::size_t f = 0; f < nf; ++f)
      if (collapsed(f) && !degenerate(&in.indices[3 * f])) ++m.dropped_degenerate;
  auto lowest_corner = [&](std::size_t f) {  // sorted_corners(f)[0], without the sort
    return std::min({internal[in.indices[3 * f]], internal[in.indices[3 * f + 1]], internal[in.indices[3 * f + 2]]});
  };
  // Two faces on the same three vertices: whether they turn opposite ways round them.
  auto reversed = [&](std::size_t f, std::size_t g) {
    const std::uint32_t* a = &in.indices[3 * f];
    const std::uint32_t* b = &in.indices[3 * g];
    const std::uint32_t a0 = internal[a[0]], a1 = internal[a[1]];
    for (int c = 0; c < 3; ++c)  // b's corner on a's first vertex: a's second follows it in the same turn
      if (internal[b[c]] == a0) return internal[b[(c + 1) % 3]] != a1;
    return false;
  };
  std::vector<std::uint32_t> bucket_start(n + 1, 0);
  for (std::size_t f = 0; f < nf; ++f)
    if (!collapsed(f)) ++bucket_start[lowest_corner(f) + 1];
  for (std::size_t i = 0; i < n; ++i) bucket_start[i + 1] += bucket_start[i];
  std::vector<std::uint32_t> bucketed(bucket_start[n]);
  {
    std::vector<std::uint32_t> fill(bucket_start.begin(), bucket_start.end() - 1);
    for (std::size_t f = 0; f < nf; ++f)
      if (!collapsed(f)) bucketed[fill[lowest_corner(f)]++] = std::uint32_t(f);
  }
  m.tri.reserve(3 * bucketed.size());
  m.face_source.reserve(bucketed.size());
  std::vector<std::pair<std::array<std::uint32_t, 3>, std::uint32_t>> bucket;
  for (std::size_t i = 0; i < n; ++i) {
    bucket.clear();
    for (std::uint32_t k = bucket_start[i]; k < bucket_start[i + 1]; ++k)
      bucket.push_back({sorted_corners(bucketed[k]), bucketed[k]});
    // The pairs differ in their face, so any sort gives this one order.
    sort_small(bucket.begin(), bucket.end(), std::less<>());
    std::size_t kept = 0;  // the face of bucket[kept] is kept for the run of duplicates after it
    for (std::size_t k = 0; k < bucket.size(); ++k) {
      if (k > 0 && bucket[k].first == bucket[kept].first) {
        ++m.dropped_duplicate;
        if (reversed(bucket[k].second, bucket[kept].second) &&
            (m.reversed_twins.empty() || m.reversed_twins.back().first != bucket[kept].second))
          m.reversed_twins.push_back({bucket[kept].second, bucket[k].second});
        continue;
      }
      kept = k;
      const std::uint32_t f = bucket[k].second;
      for (int c = 0; c < 3; ++c) m.tri.push_back(internal[in.indices[3 * std::size_t(f) + c]]);
      m.face_source.push_back(f);
    }
  }
  std::sort(m.reversed_twins.begin(), m.reversed_twins.end());
}

}  // namespace

WorkingMesh prepare_input(MeshView in, std::vector<std::uint32_t>* internal_out) {
  check_mesh(in, "input");
  WorkingMesh m;
  std::vector<std::uint32_t> used = referenced_vertices(in, m.dropped_degenerate);
  set_frame(in, used, m);
  if (in.attributes.empty()) {
    const std::vector<std::uint32_t> internal = number_vertices(in, std::move(used), m);
    add_faces(in, internal, false, m);
  } else {
    // With attributes, the working vertices are the distinct positions (the wedges on them are
    // the input's vertices): a seam is not a hole.
    const std::vector<std::uint32_t> first = first_at_same_position(in.positions, used, 1);
    std::vector<std::uint32_t> distinct;
    for (std::uint32_t v : used)
      if (first[v] == v) distinct.push_back(v);
    std::vector<std::uint32_t> internal = number_vertices(in, std::move(distinct), m);
    for (std::uint32_t v : used) internal[v] = internal[first[v]];
    add_faces(in, internal, true, m);
    if (internal_out) *internal_out = std::move(internal);
  }
  const std::size_t n = m.pos.size();
  m.faces_alive = m.face_source.size();
  m.face_alive.assign(m.faces_alive, 1);
  m.input_normal.resize(m.faces_alive);
  for (std::uint32_t f = 0; f < m.faces_alive; ++f) {
    const std::uint32_t* t = m.face(f);
    m.input_normal[f] = PackedNormal::pack(cross(m.pos[t[1]] - m.pos[t[0]], m.pos[t[2]] - m.pos[t[0]]));
  }
  m.vertices_alive = n;
  m.moved.assign(n, 0);
  m.boundary.assign(n, 0);
  m.aggregated.assign(n, 0);
  return m;
}

void WorkingMesh::rebuild_face_lists() {
  vertex_faces.rebuild(pos.size(), [&](auto emit) {
    for (std::uint32_t f = 0; f < face_alive.size(); ++f)
      if (face_alive[f])
        for (int k = 0; k < 3; ++k) emit(tri[3 * std::size_t(f) + k], f);
  });
}

void WorkingMesh::squeeze_faces(const std::vector<std::uint32_t>& vertex_to) {
  std::size_t next = 0;
  for (std::size_t f = 0; f < face_alive.size(); ++f) {
    if (!face_alive[f]) continue;
    for (int k = 0; k < 3; ++k) tri[3 * next + k] = vertex_to[tri[3 * f + k]];
    if (!corner_wedge.empty())
      for (int k = 0; k < 3; ++k) corner_wedge[3 * next + k] = corner_wedge[3 * f + k];
    input_normal[next] = input_normal[f];
    face_source[next++] = face_source[f];
  }
  tri.resize(3 * next), face_source.resize(next), input_normal.resize(next);
  if (!corner_wedge.empty()) corner_wedge.resize(3 * next);
  face_alive.assign(next, 1);
}

void WorkingMesh::squeeze_vertices(const std::vector<std::uint32_t>& vertex_to, std::size_t count) {
  squeeze_by(vertex_to, count, pos);
  squeeze_by(vertex_to, count, boundary);
  if (!corner.empty()) squeeze_by(vertex_to, count, corner);
  if (!border_spot.empty()) squeeze_by(vertex_to, count, border_spot);
  squeeze_by(vertex_to, count, moved);
  squeeze_by(vertex_to, count, aggregated);
  squeeze_by(vertex_to, count, source_vertex);
  if (!locked.empty()) squeeze_by(vertex_to, count, locked);
}

Mesh build_output(const WorkingMesh& m, MeshView input, std::vector<std::uint32_t>* vertex_source,
                  std::vector<std::uint32_t>* face_source, std::vector<std::uint32_t>* output_index) {
  // Vertices no face uses any more are dropped; survivors and faces keep their input order.
  const std::uint32_t n = std::uint32_t(m.pos.size());
  std::vector<std::uint8_t> used(n, 0);
  std::vector<std::uint32_t> faces;
  for (std::uint32_t f = 0; f < m.face_alive.size(); ++f)
    if (m.face_alive[f]) {
      faces.push_back(f);
      for (int k = 0; k < 3; ++k) used[m.tri[3 * std::size_t(f) + k]] = 1;
    }
  std::sort(faces.begin(), faces.end(),
            [&](std::uint32_t x, std::uint32_t y) { return m.face_source[x] < m.face_source[y]; });
  std::vector<std::uint32_t> survivors;
  for (std::uint32_t v = 0; v < n; ++v)
    if (used[v]) survivors.push_back(v);
  std::sort(survivors.begin(), survivors.end(),
            [&](std::uint32_t x, std::uint32_t y) { return m.source_vertex[x] < m.source_vertex[y]; });
  std::vector<std::uint32_t> remap(n, kNoVertex);
  Mesh out;
  out.positions.reserve(3 * survivors.size());
  for (std::uint32_t v : survivors) {
    remap[v] = std::uint32_t(out.positions.size() / 3);
    const Vec3 p = m.output_position(v, input);
    out.positions.insert(out.positions.end(), {p.x, p.y, p.z});
    if (vertex_source) vertex_source->push_back(m.source_vertex[v]);
  }
  out.indices.reserve(3 * faces.size());
  for (std::uint32_t f : faces) {
    for (int k = 0; k < 3; ++k) out.indices.push_back(remap[m.tri[3 * std::size_t(f) + k]]);
    if (face_source) face_source->push_back(m.face_source[f]);
  }
  if (output_index) *output_index = std::move(remap);
  return out;
}

}  // namespace qem::core
