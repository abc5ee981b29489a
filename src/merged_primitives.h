// The primitives of one glTF mesh as one surface: a mesh split by material into primitives whose
// borders meet (a truck's body, its glass and its window trim) is simplified as one mesh whose
// faces carry their primitive as their material, and split back afterwards. Its shared borders
// are then seams (a material boundary, docs/attributes.md) that collapse on both sides together,
// instead of borders each primitive must keep where they are so that no crack opens between them.
#pragma once

#include <cstdint>
#include <optional>
#include <span>

#include "qem/mesh.h"

namespace qem {

/// The parts concatenated: their vertices one part after another, each face's material its part's
/// index. Each attribute of any part is carried: a part without texture coordinates or colours gets
/// zeros (UV) or white (colour) there, constant over its faces and so without error; any other
/// attribute (normals, skin, tangents, morph offsets, the file's own) must be in every part with
/// the same kind and width. nullopt when the parts' attributes do not allow that.
std::optional<Mesh> merge_parts(std::span<const Mesh> parts);

/// Part `part` of a merged and simplified mesh: its faces (material `part`) on their vertices, with
/// the attributes of `like` (the part as it was read: their names, kinds and order).
Mesh split_part(const Mesh& merged, std::uint32_t part, const Mesh& like);

}  // namespace qem
