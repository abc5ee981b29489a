#include "core/forgetting.h"

#include <algorithm>

#include "core/fundamental_quadrics.h"
#include "core/valid_pairs.h"

namespace qem::core {

void renew_quadrics(Context& c) {
  WorkingMesh& m = c.mesh;
  face_quadrics(m, c.settings.weighting, c.settings.threads, c.quadric);
  if (c.wedges) c.wedges->renew_quadrics(m);
  const bool open = std::find(m.boundary.begin(), m.boundary.end(), std::uint8_t(1)) != m.boundary.end();
  if (!open && !c.wedges) return;  // closed, no seams: no edge planes, no edges needed
  // Without seams only the border edges get planes. Where contractions keep the topology (no
  // threshold pairs, no coincident faces dropped), an edge comes to have one face only by taking
  // the place of a border edge (it merges with one), whose ends were border vertices and stay
  // flagged (contract: boundary[a] |= boundary[b]); so the flagged vertices, a few of all, hold the
  // lower end of every border edge, and the list is unique_edges' border edges in its order.
  const bool border_only = !c.wedges && c.settings.preserve_topology && c.pairs.virtual_count == 0;
  add_constraint_planes(m,
                        border_only ? single_face_edges(m.tri, m.vertex_faces, m.boundary)
                                    : unique_edges(m.tri, m.vertex_faces, m.vertex_count()),
                        c.settings, c.wedges != nullptr, c.quadric);
}

}  // namespace qem::core
