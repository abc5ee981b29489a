// KHR_draco_mesh_compression: primitives whose geometry is a Draco bitstream are decoded with
// Debian's libdraco (Google's reference decoder) into plain accessors when a glTF document is
// loaded, so that everything after the load (reading, simplifying, writing) sees an ordinary
// document. The output is written uncompressed: qem re-packs every buffer it writes, and
// compressing again is a separate, lossy choice (gltfpack, gltf-transform) left to the user.
#pragma once

#include <tiny_gltf.h>

#include <cstddef>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <set>
#include <string>
#include <utility>

namespace qem::io::gltf {

/// tinygltf refuses a primitive whose index accessor has no buffer view, which is how a Draco
/// primitive's indices are written (the bitstream holds them). In a document's JSON, before
/// tinygltf reads it (io/gltf_prepass.h), moves each such primitive's `indices` into its extension
/// object (as `qem_indices`, where decode_draco takes it back). True when it moved one.
bool set_draco_indices_aside(nlohmann::json& doc);

/// Decodes every primitive that carries KHR_draco_mesh_compression: each accessor the extension
/// names (and the indices) gets the decoded values in a new buffer and buffer view, in its own
/// component type; the extension leaves the primitives and the document's extension lists. A
/// POINTS primitive is decoded as a point cloud; any other as faces, so a strip becomes TRIANGLES. The
/// buffer views that held the bitstreams are added to `compressed_views` (the writer drops them).
/// Throws qem::Error naming `name`, the mesh and the primitive when the bitstream or the extension
/// is malformed or does not match the accessors (an attribute's component count, a value that
/// does not fit the accessor's type). The spacing of the grid each primitive's POSITION was
/// quantized to (in the mesh's units) goes to `position_steps`, by (mesh, primitive).
using PositionSteps = std::map<std::pair<std::size_t, std::size_t>, double>;
void decode_draco(tinygltf::Model& model, const std::string& name, std::set<std::size_t>& compressed_views,
                  PositionSteps& position_steps);

}  // namespace qem::io::gltf
