#include "core/renumber.h"

#include "core/parallel_chunks.h"

namespace qem::core {

void renumber_densely(Context& c, PassState& s) {
  // A vertex lives on while a live face or a pair that is not dead has it: kNoVertex (gone), then
  // 0 (used), then the new id.
  WorkingMesh& m = c.mesh;
  std::vector<std::uint32_t> vertex_to(m.vertex_count(), kNoVertex);
  for (std::uint32_t f = 0; f < m.face_alive.size(); ++f)
    if (m.face_alive[f])
      for (int k = 0; k < 3; ++k) vertex_to[m.tri[3 * std::size_t(f) + k]] = 0;
  for (const PairRecord& r : c.pairs.pairs)
    if (r.state != kDead) vertex_to[r.v[0]] = vertex_to[r.v[1]] = 0;
  std::uint32_t count = 0;
  for (std::uint32_t& to : vertex_to)
    if (to != kNoVertex) to = count++;

  // Pairs and faces keep their order, so each one's new id is the count of survivors before it.
  side_by_side(
      c.settings.threads,
      [&] { c.pairs.squeeze(vertex_to, count, [&](std::size_t from, std::size_t to) { s.dirty[to] = s.dirty[from]; }); },
      [&] { m.squeeze_faces(vertex_to); });
  s.dirty.resize(c.pairs.pairs.size());
  m.squeeze_vertices(vertex_to, count);
  squeeze_by(vertex_to, count, c.quadric);
  squeeze_by(vertex_to, count, s.touched_in_pass);
  c.marks.assign(count, 0);
  if (c.map) c.map->renumber(vertex_to, count);
  if (c.wedges) c.wedges->renumber(vertex_to, count);
  if (c.components) c.components->renumber(vertex_to, count);
}

}  // namespace qem::core
