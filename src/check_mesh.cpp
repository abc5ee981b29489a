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
}

}  // namespace qem
