// weld_exact: merges vertices with exactly equal coordinates (see weld.h for the hash); the first
// occurrence of each position keeps its place and the original relative order.
#include "io/weld.h"

#include <bit>
#include <cstring>
#include <string>
#include <unordered_map>

#include "qem/io.h"

namespace qem {

namespace {

/// The remap of welding a mesh with attributes: vertices merge only when their position and every
/// attribute value are bit-identical (-0 folded onto +0), so wedges of a seam stay apart.
std::vector<std::uint32_t> wedge_remap(const Mesh& mesh, std::vector<std::uint32_t>& first) {
  const std::size_t nv = mesh.vertex_count();
  std::vector<std::uint32_t> remap(nv);
  std::unordered_map<std::string, std::uint32_t> seen;
  seen.reserve(nv);
  std::string key;
  auto add = [&key](double v) {
    const std::uint64_t b = std::bit_cast<std::uint64_t>(v == 0.0 ? 0.0 : v);
    key.append(reinterpret_cast<const char*>(&b), sizeof b);
  };
  for (std::size_t v = 0; v < nv; ++v) {
    key.clear();
    for (int k = 0; k < 3; ++k) add(mesh.positions[3 * v + k]);
    for (const VertexAttribute& a : mesh.attributes)
      for (std::uint32_t c = 0; c < a.components; ++c)
        add(a.values.size() == std::size_t{a.components} * nv ? a.values[a.components * v + c] : 0.0);
    auto [it, added] = seen.try_emplace(key, static_cast<std::uint32_t>(first.size()));
    if (added) first.push_back(static_cast<std::uint32_t>(v));
    remap[v] = it->second;
  }
  return remap;
}

// Keeps vertex first[n] as vertex n (first[] increasing, so compacting in place never overwrites a
// value still to be read) in every per-vertex array, and renames the faces through remap.
std::size_t compact_vertices(Mesh& mesh, const std::vector<std::uint32_t>& first, const std::vector<std::uint32_t>& remap,
                             std::size_t nv) {
  const std::size_t kept = first.size();
  for (VertexAttribute& a : mesh.attributes) {
    if (a.values.size() != std::size_t{a.components} * nv) continue;
    for (std::size_t n = 0; n < kept; ++n)
      std::memmove(&a.values[a.components * n], &a.values[a.components * std::size_t{first[n]}],
                   a.components * sizeof(double));
    a.values.resize(a.components * kept);
  }
  for (VertexProperty& p : mesh.vertex_properties) {
    if (p.values.size() != nv) continue;
    for (std::size_t n = 0; n < kept; ++n) p.values[n] = p.values[first[n]];
    p.values.resize(kept);
  }
  for (std::uint32_t& i : mesh.indices)
    if (i < nv) i = remap[i];
  return nv - kept;
}

}  // namespace

std::size_t weld_exact(Mesh& mesh) {
  const std::size_t nv = mesh.vertex_count();
  if (nv < 2) return 0;
  if (!mesh.attributes.empty()) {
    std::vector<std::uint32_t> first;
    std::vector<std::uint32_t> remap = wedge_remap(mesh, first);
    const std::size_t kept = first.size();
    if (kept == nv) return 0;
    // first[] is increasing, so compacting in place never overwrites a value still to be read.
    for (std::size_t n = 0; n < kept; ++n)
      std::memmove(&mesh.positions[3 * n], &mesh.positions[3 * std::size_t{first[n]}], 3 * sizeof(double));
    mesh.positions.resize(3 * kept);
    return compact_vertices(mesh, first, remap, nv);
  }
  std::vector<double> unique;
  unique.reserve(mesh.positions.size());
  io::VertexWelder welder(unique, nv);
  std::vector<std::uint32_t> remap(nv);
  std::vector<std::uint32_t> first;  // new index -> old index of its first occurrence
  first.reserve(nv);
  constexpr std::size_t kAhead = 16;  // vertices between prefetch and use (see VertexWelder::prefetch)
  for (std::size_t v = 0; v < nv; ++v) {
    if (v + kAhead < nv) {
      const double* a = &mesh.positions[3 * (v + kAhead)];
      welder.prefetch(a[0], a[1], a[2]);
    }
    const double* p = &mesh.positions[3 * v];
    remap[v] = welder.add(p[0], p[1], p[2]);
    if (remap[v] == first.size()) first.push_back(static_cast<std::uint32_t>(v));
  }
  const std::size_t kept = first.size();
  if (kept == nv) return 0;
  mesh.positions.swap(unique);
  mesh.positions.shrink_to_fit();
  return compact_vertices(mesh, first, remap, nv);  // no attributes here: properties and faces
}

}  // namespace qem
