#include "check_mesh.h"

#include <cmath>
#include <string>

#include "qem/error.h"

namespace qem {

void check_mesh(MeshView mesh, std::string_view what) {
  const auto fail = [&](const std::string& message) { throw Error(std::string(what) + ": " + message); };
  if (mesh.positions.size() % 3 != 0)
    fail(std::to_string(mesh.positions.size()) + " coordinates are not 3 per vertex");
  if (mesh.indices.size() % 3 != 0)
    fail(std::to_string(mesh.indices.size()) + " indices are not 3 per triangle");
  const std::size_t nv = mesh.vertex_count();
  for (std::size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= nv)
      fail("face " + std::to_string(i / 3) + " refers to vertex " + std::to_string(mesh.indices[i]) +
           ", but there are only " + std::to_string(nv) + " vertices");
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    if (!std::isfinite(mesh.positions[i]))
      fail("vertex " + std::to_string(i / 3) + " has a non-finite coordinate");
  for (const VertexAttribute& a : mesh.attributes) {
    const std::string name = "attribute '" + a.name + "'";
    if (a.components < 1 || a.components > 4)
      fail(name + " has " + std::to_string(a.components) + " components (1 to 4 allowed)");
    if (a.values.size() != std::size_t(a.components) * nv)
      fail(name + " has " + std::to_string(a.values.size()) + " values for " + std::to_string(nv) + " vertices of " +
           std::to_string(a.components) + " components");
    for (std::size_t i = 0; i < a.values.size(); ++i)
      if (!std::isfinite(a.values[i]))
        fail(name + " of vertex " + std::to_string(i / a.components) + " is not a finite number");
  }
  if (!mesh.face_materials.empty() && mesh.face_materials.size() != mesh.face_count())
    fail(std::to_string(mesh.face_materials.size()) + " face materials for " + std::to_string(mesh.face_count()) +
         " faces");
}

}  // namespace qem
