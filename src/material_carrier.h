// Faces' materials without attributes. The core keeps materials apart (a material boundary is a
// seam whose sides collapse together, docs/attributes.md) on its wedge path, which it takes for a
// mesh with attributes. A mesh with materials alone (an OBJ with `usemtl` and no `vt`/`vn`, glTF
// primitives merged without attributes) carries a constant attribute through the run, which adds
// no error and moves no placement, and loses it after.
#pragma once

#include <algorithm>
#include <cstddef>
#include <span>
#include <vector>

#include "qem/mesh.h"

namespace qem {

inline constexpr const char* kMaterialCarrier = "qem:materials";

/// Whether `mesh` has face materials and no attribute to take them through the core.
inline bool needs_material_carrier(MeshView mesh) {
  return mesh.attributes.empty() && !mesh.face_materials.empty();
}

/// The constant attribute of `vertices` vertices that takes the materials through.
inline VertexAttribute material_carrier(std::size_t vertices) {
  return {kMaterialCarrier, AttributeKind::Scalar, 1, std::vector<double>(vertices, 0.0)};
}

/// run(view): `mesh` viewed with the carrier as its one attribute.
template <class Run>
auto with_material_carrier(MeshView mesh, Run&& run) {
  const VertexAttribute carrier = material_carrier(mesh.vertex_count());
  MeshView with = mesh;
  with.attributes = std::span(&carrier, 1);
  return run(with);
}

/// `attributes` without the carrier.
inline void drop_material_carrier(std::vector<VertexAttribute>& attributes) {
  std::erase_if(attributes, [](const VertexAttribute& a) { return a.name == kMaterialCarrier; });
}

}  // namespace qem
