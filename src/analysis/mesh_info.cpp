// mesh_info: counts of the topological defects that matter to pair contraction (GH97 §3: the
// algorithm accepts non-manifold input, but users need to know what they feed it) and the facts
// `qem info` prints. Definitions match the catalogue's reference tool so numbers compare 1:1.
//
// Everything is computed from flat arrays: half-edges are bucket-sorted by their smaller vertex
// (a counting sort, O(V + F)), then each small bucket is sorted by the larger vertex, so equal
// edges are adjacent without any hashing.
#include "qem/mesh_info.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "analysis/disjoint_sets.h"
#include "check_mesh.h"
#include "io/weld.h"
#include "qem/error.h"

namespace qem {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

bool has_repeated_index(const std::uint32_t* t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

/// Exactly zero cross product, the same test as the reference tool (no tolerance: a tolerance would
/// depend on the model's scale).
bool zero_area(std::span<const double> p, const std::uint32_t* t) {
  const double* a = &p[3 * std::size_t(t[0])];
  const double* b = &p[3 * std::size_t(t[1])];
  const double* c = &p[3 * std::size_t(t[2])];
  double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
  double vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
  double cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
  return cx == 0.0 && cy == 0.0 && cz == 0.0;
}

void check_input(MeshView mesh) {
  check_mesh(mesh, "mesh_info");
  // Corners are numbered 3f + k in 32 bits, kNone reserved.
  if (mesh.indices.size() >= std::size_t(kNone))
    throw Error("mesh_info: too many faces (" + std::to_string(mesh.face_count()) + ")");
}

/// Faces with the same vertex set as an earlier face, over faces without repeated indices.
std::size_t count_duplicates(std::span<const std::uint32_t> idx, const std::vector<std::uint8_t>& repeated) {
  std::vector<std::array<std::uint32_t, 3>> keys;
  keys.reserve(repeated.size());
  for (std::size_t f = 0; f < repeated.size(); ++f) {
    if (repeated[f]) continue;
    std::array<std::uint32_t, 3> k = {idx[3 * f], idx[3 * f + 1], idx[3 * f + 2]};
    std::sort(k.begin(), k.end());
    keys.push_back(k);
  }
  std::sort(keys.begin(), keys.end());
  return keys.size() - std::size_t(std::unique(keys.begin(), keys.end()) - keys.begin());
}

/// Half-edges of the faces without repeated indices, grouped by undirected edge: bucket `lo` holds
/// (hi << 32 | half-edge id) for every half-edge whose smaller vertex is lo, sorted.
struct EdgeBuckets {
  std::vector<std::uint32_t> start;  // vertex_count + 1 offsets into slots
  std::vector<std::uint64_t> slots;
};

EdgeBuckets bucket_half_edges(std::span<const std::uint32_t> idx, const std::vector<std::uint8_t>& repeated,
                              std::size_t nv) {
  EdgeBuckets b;
  b.start.assign(nv + 1, 0);
  const std::size_t nf = repeated.size();
  for (std::size_t f = 0; f < nf; ++f) {
    if (repeated[f]) continue;
    for (int k = 0; k < 3; ++k) ++b.start[std::min(idx[3 * f + k], idx[3 * f + (k + 1) % 3]) + 1];
  }
  for (std::size_t v = 0; v < nv; ++v) b.start[v + 1] += b.start[v];
  b.slots.resize(b.start[nv]);
  std::vector<std::uint32_t> fill(b.start.begin(), b.start.end() - 1);
  for (std::size_t f = 0; f < nf; ++f) {
    if (repeated[f]) continue;
    for (int k = 0; k < 3; ++k) {
      std::uint32_t u = idx[3 * f + k], w = idx[3 * f + (k + 1) % 3];
      std::uint32_t lo = std::min(u, w), hi = std::max(u, w);
      b.slots[fill[lo]++] = (std::uint64_t(hi) << 32) | std::uint64_t(3 * f + k);
    }
  }
  // Buckets average about three entries (six half-edges per vertex, half of them stored at the
  // smaller end), so sorting each is cheap; the half-edge id in the low bits keeps it deterministic.
  for (std::size_t v = 0; v < nv; ++v)
    std::sort(b.slots.begin() + b.start[v], b.slots.begin() + b.start[v + 1]);
  return b;
}

/// The corner (3 * face + k) of face `f` that holds vertex `v`.
std::uint32_t corner_of(std::span<const std::uint32_t> idx, std::uint32_t f, std::uint32_t v) {
  std::uint32_t c = 3 * f;
  return idx[c] == v ? c : idx[c + 1] == v ? c + 1 : c + 2;
}

}  // namespace

MeshInfo mesh_info(MeshView mesh) {
  check_input(mesh);
  const std::span<const std::uint32_t> idx = mesh.indices;
  const std::size_t nv = mesh.vertex_count(), nf = mesh.face_count();

  MeshInfo info;
  info.vertices = nv;
  info.faces = nf;
  info.box = bounding_box(mesh);

  // --- per face: references, repeated indices, zero area ----------------------------------------
  std::vector<std::uint8_t> used(nv, 0), repeated(nf, 0);
  std::size_t repeated_count = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t* t = &idx[3 * f];
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
    if (has_repeated_index(t)) {
      repeated[f] = 1;
      ++repeated_count;
    } else if (zero_area(mesh.positions, t)) {
      ++info.zero_area_faces;
    }
  }
  info.degenerate_faces = repeated_count + info.zero_area_faces;
  std::size_t used_count = 0;
  for (std::uint8_t u : used) used_count += u;
  info.unreferenced_vertices = nv - used_count;
  info.duplicate_faces = count_duplicates(idx, repeated);

  // --- edges: boundary, non-manifold, orientation, and the fans around each vertex --------------
  EdgeBuckets buckets = bucket_half_edges(idx, repeated, nv);
  analysis::DisjointSets corners(3 * nf);  // corners of one vertex joined across 2-face edges
  analysis::DisjointSets boundary(nv);     // vertices joined along boundary edges
  std::vector<std::uint8_t> on_boundary(nv, 0);
  for (std::uint32_t lo = 0; lo < nv; ++lo) {
    const std::uint32_t end = buckets.start[lo + 1];
    for (std::uint32_t i = buckets.start[lo]; i < end;) {
      const std::uint32_t hi = std::uint32_t(buckets.slots[i] >> 32);
      std::uint32_t j = i + 1;
      while (j < end && std::uint32_t(buckets.slots[j] >> 32) == hi) ++j;
      ++info.edges;
      const std::uint32_t count = j - i;
      if (count == 1) {
        ++info.boundary_edges;
        boundary.unite(lo, hi);
        on_boundary[lo] = on_boundary[hi] = 1;
      } else if (count > 2) {
        ++info.non_manifold_edges;
      } else {
        const std::uint32_t h1 = std::uint32_t(buckets.slots[i]), h2 = std::uint32_t(buckets.slots[i + 1]);
        // A half-edge runs lo -> hi when its start corner holds lo; consistently oriented
        // neighbours traverse their shared edge in opposite directions.
        if ((idx[h1] == lo) == (idx[h2] == lo)) ++info.orientation_conflicts;
        const std::uint32_t f1 = h1 / 3, f2 = h2 / 3;
        corners.unite(corner_of(idx, f1, lo), corner_of(idx, f2, lo));
        corners.unite(corner_of(idx, f1, hi), corner_of(idx, f2, hi));
      }
      i = j;
    }
  }
  buckets = {};

  // A vertex whose corners fall into more than one set has more than one fan.
  std::vector<std::uint32_t> fan(nv, kNone);
  std::vector<std::uint8_t> several_fans(nv, 0);
  for (std::uint32_t f = 0; f < nf; ++f) {
    if (repeated[f]) continue;
    for (std::uint32_t c = 3 * f; c < 3 * f + 3; ++c) {
      const std::uint32_t v = idx[c], root = corners.find(c);
      if (fan[v] == kNone)
        fan[v] = root;
      else if (fan[v] != root)
        several_fans[v] = 1;
    }
  }
  for (std::uint8_t s : several_fans) info.non_manifold_vertices += s;

  for (std::uint32_t v = 0; v < nv; ++v)
    if (on_boundary[v] && boundary.find(v) == v) ++info.boundary_loops;

  // --- components: faces joined through shared vertices (all faces, as in the reference) -------
  analysis::DisjointSets parts(nv);
  for (std::size_t f = 0; f < nf; ++f) {
    parts.unite(idx[3 * f], idx[3 * f + 1]);
    parts.unite(idx[3 * f], idx[3 * f + 2]);
  }
  for (std::uint32_t v = 0; v < nv; ++v)
    if (used[v] && parts.find(v) == v) ++info.components;

  // --- Euler characteristic and genus: chi = V - E + F = 2c - 2g for closed orientable surfaces --
  info.euler = (long long)used_count - (long long)info.edges + (long long)(nf - repeated_count);
  const bool closed_manifold = info.boundary_edges == 0 && info.manifold() && repeated_count == 0;
  if (closed_manifold && info.orientation_conflicts == 0 && info.components > 0)
    info.genus = (2 * (long long)info.components - info.euler) / 2;

  // --- seams and materials ------------------------------------------------------------------------
  {
    std::vector<double> unique;
    unique.reserve(mesh.positions.size());
    io::VertexWelder welder(unique, nv);
    std::vector<std::uint32_t> count(nv, 0);  // vertices per distinct position
    for (std::size_t v = 0; v < nv; ++v) {
      const double* p = &mesh.positions[3 * v];
      if (++count[welder.add(p[0], p[1], p[2])] == 2) ++info.seam_vertices;
    }
  }
  if (!mesh.face_materials.empty()) {
    std::vector<std::uint32_t> m(mesh.face_materials.begin(), mesh.face_materials.end());
    std::sort(m.begin(), m.end());
    info.materials = std::size_t(std::unique(m.begin(), m.end()) - m.begin());
  }
  return info;
}

}  // namespace qem
