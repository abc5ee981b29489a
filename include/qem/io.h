// Reading and writing meshes: OBJ, PLY (ASCII, binary little/big endian), STL (ASCII, binary), OFF,
// glTF 2.0 (.gltf, .glb: the whole scene merged into one mesh; qem/gltf.h keeps the document).
// Readers triangulate polygons (fan), validate everything (indices, counts, finite coordinates)
// and throw qem::Error naming the file and the line or element. Writers write to a temporary file
// beside the target and rename it, so a failed run never leaves a half-written mesh.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "qem/error.h"
#include "qem/mesh.h"

namespace qem {

/// Gltf: .gltf or .glb. load_mesh merges every triangle primitive of the default scene into one
/// Mesh in world space (GltfDocument::scene_mesh); save_mesh writes a minimal glTF, .glb or .gltf
/// by extension (serialize_gltf; `binary` chooses for serialize_mesh). Keeping the rest of a glTF
/// file needs qem/gltf.h.
enum class FileFormat { Auto, Obj, Ply, Stl, Off, Gltf };

/// The format named by a path's extension (case-insensitive), or Auto if unknown.
FileFormat format_from_extension(const std::string& path);

/// How `weld` behaves: STL always stores each triangle's corners separately, so it is welded
/// unless explicitly turned off.
enum class Weld { Auto, On, Off };

struct LoadOptions {
  FileFormat format = FileFormat::Auto;  ///< Auto: by extension, then by content
  Weld weld = Weld::Auto;                ///< merge exactly coincident vertices (Auto = STL only)
  bool keep_vertex_properties = false;   ///< PLY: keep extra scalar vertex properties
  /// Read normals, texture coordinates, vertex colours and materials into Mesh::attributes,
  /// face_materials, material_names and material_library (docs/attributes.md). Off: positions and
  /// faces only, and an OBJ's vertices are its `v` lines even where faces index `vt`/`vn`.
  bool read_attributes = true;
};

/// What a reader found and did, for `qem info` and the CLI summary.
struct LoadReport {
  FileFormat format = FileFormat::Auto;
  bool binary = false;
  std::size_t polygons_triangulated = 0;  ///< input faces with more than 3 corners
  std::size_t vertices_welded = 0;        ///< vertices removed by welding
  bool double_precision = false;          ///< PLY: coordinates were stored as double
  /// What was read leniently instead of refused (e.g. a PLY header line with an unknown keyword,
  /// skipped), each as "<name>, line <line>: <what>" like an error message; the CLI prints them.
  std::vector<std::string> warnings;
};

/// Reads a mesh file. Throws qem::Error on any malformed input; never crashes or hangs.
Mesh load_mesh(const std::string& path, const LoadOptions& options = {}, LoadReport* report = nullptr);

/// Parses a mesh held in memory; `name` is used in error messages. Used by the fuzzers and tests.
Mesh parse_mesh(std::string_view bytes, FileFormat format, const std::string& name,
                const LoadOptions& options = {}, LoadReport* report = nullptr);

struct SaveOptions {
  FileFormat format = FileFormat::Auto;  ///< Auto: by extension
  bool binary = true;                    ///< PLY, STL: binary (little endian) or ASCII; glTF: .glb
  bool double_precision = false;         ///< PLY: write double coordinates/properties instead of float
};

/// Writes a mesh atomically (temporary file in the same folder, then rename).
void save_mesh(const std::string& path, const Mesh& mesh, const SaveOptions& options = {});

/// Serialises a mesh to bytes in the given format (no file involved).
std::string serialize_mesh(const Mesh& mesh, FileFormat format, bool binary = true);
/// Same, with every save option; `options.format` must not be Auto.
std::string serialize_mesh(const Mesh& mesh, const SaveOptions& options);

/// Merges vertices with exactly equal coordinates; returns how many were removed. When the mesh has
/// attributes, only vertices whose attribute values are equal too (a seam's wedges stay apart).
std::size_t weld_exact(Mesh& mesh);

}  // namespace qem
