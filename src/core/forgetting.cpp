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
  add_constraint_planes(m, unique_edges(m.tri, m.vertex_faces, m.vertex_count()), c.settings, c.wedges != nullptr,
                        c.quadric);
}

}  // namespace qem::core
