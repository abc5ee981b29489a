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

namespace qem::view {

/// How the page lays the levels out.
enum class ViewMode {
  Single,   ///< one mesh (or several shown one at a time without the LOD wording)
  Chain,    ///< an LOD chain: a slider walks the levels, finest first
  Compare,  ///< exactly two meshes side by side with one shared (linked) camera
};
const char* to_string(ViewMode mode);

struct ViewLevel {
  std::string name;  ///< shown in the page (usually the file name)
  Mesh mesh;
  /// Approximation error of this level (distance units), NaN when unknown (shown as "n/a").
  double error = std::numeric_limits<double>::quiet_NaN();
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
/// (so large coordinates keep their precision), indices as little-endian Uint32. Deterministic.
/// Throws qem::Error for an empty scene, a compare scene without exactly two levels, or a level
/// with out-of-range indices.
std::map<std::string, std::string> scene_files(const ViewScene& scene);

}  // namespace qem::view
