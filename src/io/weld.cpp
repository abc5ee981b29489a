// weld_exact: merges vertices with exactly equal coordinates (see weld.h for the hash); the first
// occurrence of each position keeps its place and the original relative order.
#include "io/weld.h"

#include "qem/io.h"

namespace qem {

std::size_t weld_exact(Mesh& mesh) {
  const std::size_t nv = mesh.vertex_count();
  if (nv < 2) return 0;
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
  for (VertexProperty& p : mesh.vertex_properties) {
    if (p.values.size() != nv) continue;
    // first[] is increasing, so compacting in place never overwrites a value still to be read.
    for (std::size_t n = 0; n < kept; ++n) p.values[n] = p.values[first[n]];
    p.values.resize(kept);
  }
  for (std::uint32_t& i : mesh.indices)
    if (i < nv) i = remap[i];
  return nv - kept;
}

}  // namespace qem
