// EXT_meshopt_compression: buffer views stored as meshoptimizer's vertex and index codecs (what
// gltfpack -cc and gltf-transform meshopt write) are decoded with Debian's libmeshoptimizer when a
// glTF document is loaded, into the place the view names in its (fallback) buffer, so that
// everything after the load sees an ordinary document; it is written uncompressed, as Draco is
// (io/gltf_draco.h).
#pragma once

#include <tiny_gltf.h>

#include <nlohmann/json_fwd.hpp>
#include <string>

namespace qem::io::gltf {

/// tinygltf cannot load a buffer that has no data, which is what a fallback buffer (marked
/// `"fallback": true` in its EXT_meshopt_compression object) usually is. In a document's JSON,
/// before tinygltf reads it (io/gltf_prepass.h), gives each such buffer one byte of embedded data
/// and keeps its real length in the extension object (`qem_byteLength`), where decode_meshopt
/// takes it back. True when it changed one.
bool set_fallback_buffers_aside(nlohmann::json& doc);

/// Decodes every buffer view that carries EXT_meshopt_compression (modes ATTRIBUTES, TRIANGLES and
/// INDICES; filters NONE, OCTAHEDRAL, QUATERNION and EXPONENTIAL) into its place in its buffer,
/// restores the fallback buffers' lengths, and removes the extension from the views, the buffers
/// and the document's extension lists. Throws qem::Error naming `name` and the buffer view when the
/// extension's numbers are out of range or the data does not decode.
void decode_meshopt(tinygltf::Model& model, const std::string& name);

}  // namespace qem::io::gltf
