// Where the compressed primitives of one glTF mesh meet. Draco quantizes each primitive's positions
// on a grid of its own bounding box, so a vertex that two primitives share (the line where a
// truck's glass meets its body) is decoded at two positions up to a grid step apart. Matched by
// exact position, the primitives would then be simplified apart, each moving its side of the line:
// cracks. Snapped together first, they are joined as the uncompressed document's are
// (merged_primitives.h).
#pragma once

#include <cstddef>
#include <span>

#include "qem/gltf.h"
#include "qem/mesh.h"

namespace qem {

/// Moves each border vertex of parts[k] (on an edge that one face of the part has, the part welded
/// by position) onto the nearest border vertex of an earlier part that lies within
/// (steps[j] + steps[k]) / 2 of it on each axis: the farthest apart two quantizations of one point
/// can be, with steps[k] the spacing of part k's grid (0 for a part stored unquantized, which is
/// matched exactly by the caller and so only snapped to quantized parts). Vertices of one part at
/// one position move together. Returns the number of vertices moved.
std::size_t snap_quantized_borders(std::span<Mesh> parts, std::span<const double> steps);

/// snap_quantized_borders over the primitives of each placement (GltfPrimitiveInfo::placement: one
/// mesh, or meshes the same nodes draw): meshes[k] is primitive primitives[k] of a document whose
/// primitives() are `info`, in document order, with their position_step.
void snap_quantized_primitives(std::span<Mesh> meshes, std::span<const std::size_t> primitives,
                               const std::vector<GltfPrimitiveInfo>& info);

}  // namespace qem
