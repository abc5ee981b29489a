// The data a viewer page shows, as files: `data/scene.json` describing a list of levels and one
// binary buffer per array. A level list is just an array of meshes with {faces, vertices, error},
// so an LOD chain, a progressive record or an original-vs-simplified pair all share one format
// (docs/viewer.md describes it field by field).
#pragma once

#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "qem/mesh.h"
#include "view/web_assets.h"

namespace qem::view {

/// How the page lays the levels out.
enum class ViewMode {
  Single,   ///< one mesh (or several shown one at a time without the LOD wording)
  Chain,    ///< an LOD chain: a slider walks the levels, finest first
  Compare,  ///< exactly two meshes side by side with one shared (linked) camera
};
const char* to_string(ViewMode mode);

/// How the page draws the faces of one material of a mesh (OBJ `usemtl` + its .mtl entry).
struct ViewMaterial {
  std::string name;
  double color[3] = {1, 1, 1};  ///< diffuse colour, sRGB
  double opacity = 1;
  std::string texture;  ///< key in ViewLevel::files of the diffuse texture, "" when none
};

struct ViewLevel {
  std::string name;  ///< shown in the page (usually the file name)
  /// The geometry: drawn with its normals, first texture coordinates and first colours when it
  /// has them; for a glTF level, used for the counts, the frame and the error only.
  Mesh mesh;
  /// Approximation error of this level (distance units), NaN when unknown (shown as "n/a").
  double error = std::numeric_limits<double>::quiet_NaN();
  /// One per material of mesh.face_materials (empty: every face gets the page's default look).
  std::vector<ViewMaterial> materials;
  /// Files the page loads for this level (textures; a glTF document and its buffers and images),
  /// keyed by their path relative to the model's folder and served under data/level<i>/.
  FileSet files;
  /// When not empty, the key in `files` of a glTF document that the page shows as itself (its
  /// materials, node hierarchy, skins and animations) instead of `mesh`.
  std::string gltf;
};

struct ViewScene {
  ViewMode mode = ViewMode::Single;
  std::string title;
  std::vector<ViewLevel> levels;
};

/// The vertex property the page colours as an error heat map.
inline constexpr const char* kHeatProperty = "distance";

/// The scene's files, keyed by path relative to the page ("data/scene.json", "data/level0.pos.f32",
/// ...). Positions are stored as little-endian Float32 relative to the scene's bounding-box centre
/// (so large coordinates keep their precision), indices as little-endian Uint32, normals, texture
/// coordinates, colours as Float32 and face materials as Uint32; a level's `files` go under
/// data/level<i>/. Deterministic. Throws qem::Error for an empty scene, a compare scene without
/// exactly two levels, or a level with out-of-range indices, attribute arrays of the wrong size,
/// face materials without a material, or a texture or glTF key missing from its files.
std::map<std::string, std::string> scene_files(const ViewScene& scene);

}  // namespace qem::view
