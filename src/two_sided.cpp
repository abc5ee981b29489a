#include "two_sided.h"

#include <algorithm>
#include <numeric>
#include <utility>

#include "core/same_position.h"

namespace qem {

namespace {

bool flips_with_the_side(AttributeKind kind) { return kind == AttributeKind::Normal || kind == AttributeKind::Tangent; }

// The twin of input face f, or nullptr.
const TwinFaces* twin_of(std::span<const TwinFaces> twins, std::uint32_t f) {
  const auto it = std::lower_bound(twins.begin(), twins.end(), f,
                                   [](const TwinFaces& t, std::uint32_t face) { return t.first < face; });
  return it != twins.end() && it->first == f ? &*it : nullptr;
}

bool has_sided_attribute(const Mesh& mesh) {
  return std::any_of(mesh.attributes.begin(), mesh.attributes.end(),
                     [](const VertexAttribute& a) { return flips_with_the_side(a.kind); });
}

}  // namespace

std::vector<std::uint32_t> faces_on_twinned_rims(const Mesh& mesh, std::span<const std::uint32_t> face_source,
                                                 std::span<const TwinFaces> twins, unsigned threads) {
  const std::size_t nf = mesh.face_count();
  std::vector<std::uint32_t> all(mesh.vertex_count());
  std::iota(all.begin(), all.end(), 0u);
  // Welded by position: the wedges of a seam are one point, so a seam is not a border.
  const std::vector<std::uint32_t> point = core::first_at_same_position(mesh.positions, std::move(all), threads);
  std::vector<std::pair<std::uint64_t, std::uint32_t>> edges;  // (lower point, higher point), face
  edges.reserve(3 * nf);
  for (std::uint32_t f = 0; f < nf; ++f) {
    if (!twin_of(twins, face_source[f])) continue;
    for (int c = 0; c < 3; ++c) {  // only the twinned faces' edges can be the rims asked for...
      std::uint32_t a = point[mesh.indices[3 * std::size_t(f) + c]], b = point[mesh.indices[3 * std::size_t(f) + (c + 1) % 3]];
      if (a > b) std::swap(a, b);
      edges.push_back({(std::uint64_t(a) << 32) | b, f});
    }
  }
  if (edges.empty()) return {};
  // ...but an edge is a border only if no face at all has it besides: the other faces' edges too,
  // where they share a point with a twinned face's edge.
  std::vector<std::uint8_t> near(mesh.vertex_count(), 0);
  for (const auto& e : edges) near[e.first >> 32] = 1, near[e.first & 0xffffffffu] = 1;
  for (std::uint32_t f = 0; f < nf; ++f) {
    if (twin_of(twins, face_source[f])) continue;
    for (int c = 0; c < 3; ++c) {
      std::uint32_t a = point[mesh.indices[3 * std::size_t(f) + c]], b = point[mesh.indices[3 * std::size_t(f) + (c + 1) % 3]];
      if (!near[a] || !near[b]) continue;
      if (a > b) std::swap(a, b);
      edges.push_back({(std::uint64_t(a) << 32) | b, 0xffffffffu});
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::uint32_t> faces;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    if (j == i + 1 && edges[i].second != 0xffffffffu) faces.push_back(edges[i].second);
    i = j;
  }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

std::vector<std::uint32_t> faces_with_twins(std::span<const std::uint32_t> face_source,
                                            std::span<const TwinFaces> twins) {
  std::vector<std::uint32_t> faces;
  for (std::uint32_t f = 0; f < face_source.size(); ++f)
    if (twin_of(twins, face_source[f])) faces.push_back(f);
  return faces;
}

std::size_t twin_vertices_needed(const Mesh& mesh, std::span<const std::uint32_t> faces) {
  if (!has_sided_attribute(mesh)) return 0;
  std::vector<std::uint32_t> corners;
  for (std::uint32_t f : faces)
    for (int c = 0; c < 3; ++c) corners.push_back(mesh.indices[3 * std::size_t(f) + c]);
  std::sort(corners.begin(), corners.end());
  return std::size_t(std::unique(corners.begin(), corners.end()) - corners.begin());
}

void add_reversed_twins(SimplifyResult& result, std::span<const std::uint32_t> faces, std::span<const TwinFaces> twins) {
  Mesh& mesh = result.mesh;
  const std::size_t nv = mesh.vertex_count();
  // Each front vertex's back vertex: itself, or a copy whose normal turns the other way.
  std::vector<std::uint32_t> back(nv);
  std::iota(back.begin(), back.end(), 0u);
  if (has_sided_attribute(mesh)) {
    const bool sources = result.vertex_source.size() == nv;
    std::vector<std::uint8_t> used(nv, 0);
    for (std::uint32_t f : faces)
      for (int c = 0; c < 3; ++c) used[mesh.indices[3 * std::size_t(f) + c]] = 1;
    for (std::uint32_t v = 0; v < nv; ++v) {
      if (!used[v]) continue;
      back[v] = std::uint32_t(mesh.vertex_count());
      for (int k = 0; k < 3; ++k) mesh.positions.push_back(mesh.positions[3 * std::size_t(v) + k]);
      for (VertexAttribute& a : mesh.attributes) {
        const std::size_t n = a.components;
        for (std::size_t k = 0; k < n; ++k) {
          double x = a.values[n * v + k];
          // A normal turns round; a tangent keeps its direction (the UVs are the same) and its
          // handedness flips, so that the bitangent stays the front's.
          if (a.kind == AttributeKind::Normal || (a.kind == AttributeKind::Tangent && k == 3)) x = -x;
          a.values.push_back(x);
        }
      }
      for (VertexProperty& p : mesh.vertex_properties) p.values.push_back(p.values[v]);
      if (sources) result.vertex_source.push_back(result.vertex_source[v]);
    }
  }
  const bool sources = result.face_source.size() == mesh.face_count();
  for (std::uint32_t f : faces) {
    const std::uint32_t* t = &mesh.indices[3 * std::size_t(f)];
    const std::uint32_t a = back[t[0]], b = back[t[2]], c = back[t[1]];  // the opposite turn
    mesh.indices.insert(mesh.indices.end(), {a, b, c});
    if (!mesh.face_materials.empty()) mesh.face_materials.push_back(mesh.face_materials[f]);
    if (sources) result.face_source.push_back(twin_of(twins, result.face_source[f])->second);
  }
  result.twin_faces += faces.size();
}

}  // namespace qem
