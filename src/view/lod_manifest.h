// The LOD manifest `qem view` accepts in place of a list of meshes: a JSON file naming the levels
// of a chain, finest first, with their face counts and errors (docs/viewer.md).
//   {"levels": [{"path": "bunny_10k.ply", "faces": 10000, "error": 0.0012}, ...]}
// A bare array of such objects, or of path strings, is accepted too; "file" or "mesh" may stand
// for "path". Paths are relative to the manifest's folder.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace qem::view {

struct ManifestLevel {
  std::string path;       ///< resolved against the manifest's folder
  std::size_t faces = 0;  ///< 0 = not given; otherwise checked against the loaded mesh
  std::size_t vertices = 0;
  double error = std::numeric_limits<double>::quiet_NaN();  ///< NaN = not given
};

/// True when `path` looks like a manifest (extension .json), not a mesh.
bool is_manifest_path(const std::string& path);

/// Parses manifest text; `path` names it in errors and anchors relative level paths.
/// Throws qem::Error naming the file and the level for anything malformed.
std::vector<ManifestLevel> parse_lod_manifest(const std::string& text, const std::string& path);

/// Reads and parses a manifest file.
std::vector<ManifestLevel> read_lod_manifest(const std::string& path);

}  // namespace qem::view
