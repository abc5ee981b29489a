#include "qem/mesh.h"

#include <cmath>

#include "geometry/box.h"

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

Box bounding_box(MeshView mesh) { return box_of_points(mesh.positions); }

}  // namespace qem
