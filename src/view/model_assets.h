// Loading a model for the viewer with what it looks like: an OBJ's material library (.mtl) and
// its diffuse textures, or a glTF document kept whole (with its external buffers and images) so
// that the page shows its materials, node hierarchy, skins and animations. Only files that the
// model references and that lie inside its folder are read (safe_path.h): `qem view` serves them.
#pragma once

#include <string>
#include <vector>

#include "qem/io.h"
#include "view/scene.h"

namespace qem::view {

/// The level for the model at `path`: its mesh (load_mesh with `options`), and
///  - for OBJ with `mtllib`: one ViewMaterial per material name, with the .mtl's Kd, d and map_Kd
///    (textures resolved relative to the .mtl, as the MTL format says);
///  - for PLY with face colours (materials named "rgb(R,G,B)"): one ViewMaterial per colour;
///  - for glTF (.gltf/.glb): the document's bytes as `gltf`, with every buffer and image that it
///    references by a relative URI.
/// A reference that is missing or lies outside the model's folder is skipped with a note in
/// `warnings` (the page then shows the model without it). Throws qem::Error when the model itself
/// cannot be read.
ViewLevel load_view_level(const std::string& path, const LoadOptions& options,
                          std::vector<std::string>* warnings);

/// The URIs of a glTF document's buffers and images that name files (not `data:` URIs), as
/// written; `bytes` is a .gltf (JSON) or a .glb. Throws qem::Error on a malformed document.
std::vector<std::string> gltf_external_uris(const std::string& bytes, const std::string& name);

}  // namespace qem::view
