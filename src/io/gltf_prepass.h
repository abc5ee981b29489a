// Changes made to a glTF document's JSON before tinygltf parses it, for the two kinds of valid
// file that tinygltf cannot read as written: Draco primitives (index accessors without a buffer
// view, io/gltf_draco.h) and EXT_meshopt_compression's fallback buffers (no data, io/gltf_meshopt.h).
// Each change is undone by the decoder that follows the load.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace qem::io::gltf {

/// Whether a document's bytes are a .glb (the binary container's magic), not a .gltf's JSON.
bool is_glb(std::string_view bytes);

/// Whether a document's JSON (json_of) names either compression extension: the test that decides
/// whether the load must decode (and the viewer serve the document decoded).
bool names_compression(std::string_view json);

/// The JSON of a glTF document's bytes: the whole text of a .gltf, or a .glb's JSON chunk (glTF 2.0
/// §4.4); nullopt when a .glb has none within its bytes.
std::optional<std::string_view> json_of(std::string_view bytes);

/// A document's bytes (.gltf JSON or .glb) with those changes made, or "" when none is needed (the
/// document uses neither extension, or its bytes are for tinygltf to refuse with its own message).
/// A .glb keeps its BIN chunk as it is; its JSON chunk is rewritten.
std::string prepare_for_tinygltf(std::string_view bytes);

}  // namespace qem::io::gltf
