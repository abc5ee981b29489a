#include "core/forgetting.h"

#include <algorithm>
#include <vector>

#include "core/fundamental_quadrics.h"
#include "core/seam_planes.h"
#include "core/valid_pairs.h"

namespace qem::core {

void renew_quadrics(Context& c) {
  WorkingMesh& m = c.mesh;
  const Settings& s = c.settings;
  c.quadric = face_quadrics(m, s.weighting, s.threads);
  const bool open = std::find(m.boundary.begin(), m.boundary.end(), std::uint8_t(1)) != m.boundary.end();
  if (!open && !c.wedges) return;  // closed, no seams: no edge planes
  const std::vector<Edge> edges = unique_edges(m.tri, m.vertex_faces, m.vertex_count());
  if (open) add_boundary_planes(m, edges, s.boundary_weight, s.weighting, c.quadric);
  if (!c.wedges) return;
  c.wedges->renew_quadrics(m);
  add_seam_planes(m, edges, s.seam_weight, s.weighting, c.quadric);
}

}  // namespace qem::core
