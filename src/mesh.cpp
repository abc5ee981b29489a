#include "qem/mesh.h"

#include <cmath>
#include <limits>

namespace qem {

const VertexProperty* Mesh::find_property(const std::string& name) const {
  for (const VertexProperty& p : vertex_properties)
    if (p.name == name) return &p;
  return nullptr;
}

const VertexAttribute* Mesh::find_attribute(AttributeKind kind) const {
  for (const VertexAttribute& a : attributes)
    if (a.kind == kind) return &a;
  return nullptr;
}

double Box::diagonal() const {
  double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

Box bounding_box(MeshView mesh) {
  Box box;
  if (mesh.positions.size() < 3) return box;
  for (int k = 0; k < 3; ++k) {
    box.lo[k] = std::numeric_limits<double>::infinity();
    box.hi[k] = -std::numeric_limits<double>::infinity();
  }
  for (std::size_t i = 0; i + 2 < mesh.positions.size(); i += 3)
    for (int k = 0; k < 3; ++k) {
      box.lo[k] = std::fmin(box.lo[k], mesh.positions[i + k]);
      box.hi[k] = std::fmax(box.hi[k], mesh.positions[i + k]);
    }
  return box;
}

}  // namespace qem
