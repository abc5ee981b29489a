// qem: triangle mesh simplification with quadric error metrics.
// The mesh type exchanged by the whole public API: plain arrays, so callers with their own mesh
// types can fill it (or a MeshView over their buffers) without a conversion layer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace qem {

/// A named per-vertex scalar carried through I/O (PLY properties such as `k1`, `k2`, `distance`).
struct VertexProperty {
  std::string name;
  std::vector<double> values;  ///< one value per vertex
};

/// What a per-vertex attribute is, which decides how simplification treats it.
enum class AttributeKind : std::uint8_t {
  Normal,        ///< a direction: renormalised after interpolation; its jumps are creases
  TexCoord,      ///< texture coordinates: its jumps are UV seams
  Color,         ///< RGB or RGBA in [0, 1]: clamped after interpolation
  JointIndices,  ///< skin joint ids: never interpolated, taken from the surviving vertex
  JointWeights,  ///< skin weights: renormalised to sum to 1
  Tangent,       ///< glTF TANGENT (xyz + handedness): recomputed or dropped by writers
  Scalar,        ///< any other value: interpolated linearly
};

/// A per-vertex attribute: `components` values for every vertex, one vertex after another.
/// A vertex is a wedge: one position may appear as several vertices whose attributes differ
/// (split at a UV seam, a normal crease, a colour boundary), as in glTF, and as readers make from
/// OBJ's face-varying `vt`/`vn` indices. Simplification treats such vertices as one point of the
/// surface whose attributes jump there (a seam), not as a hole.
struct VertexAttribute {
  std::string name;  ///< glTF semantic (NORMAL, TEXCOORD_0, COLOR_0, ...) or the file's own name
  AttributeKind kind = AttributeKind::Scalar;
  std::uint32_t components = 1;  ///< 1..4
  std::vector<double> values;    ///< components x vertex count
};

/// An indexed triangle mesh. `positions` holds x,y,z per vertex; `indices` holds 3 per triangle.
struct Mesh {
  std::vector<double> positions;
  std::vector<std::uint32_t> indices;
  /// Optional per-vertex scalars; readers fill them only when asked (LoadOptions).
  std::vector<VertexProperty> vertex_properties;
  /// Appearance and other per-vertex data (normals, texture coordinates, colours, skin weights).
  std::vector<VertexAttribute> attributes;
  /// The material of each face (empty: all faces material 0). Faces of different materials never
  /// merge: a material boundary is a seam.
  std::vector<std::uint32_t> face_materials;
  /// Material names, indexed by face_materials (OBJ `usemtl`), and the library that defines them
  /// (OBJ `mtllib`, referenced, not read).
  std::vector<std::string> material_names;
  std::string material_library;

  std::size_t vertex_count() const { return positions.size() / 3; }
  std::size_t face_count() const { return indices.size() / 3; }
  /// The values of a named vertex property, or nullptr.
  const VertexProperty* find_property(const std::string& name) const;
  /// The first attribute of a kind, or nullptr.
  const VertexAttribute* find_attribute(AttributeKind kind) const;
};

/// A read-only view of caller-owned buffers: `positions` (3 per vertex), `indices` (3 per face).
struct MeshView {
  std::span<const double> positions;
  std::span<const std::uint32_t> indices;
  std::span<const VertexAttribute> attributes;    ///< see Mesh::attributes
  std::span<const std::uint32_t> face_materials;  ///< see Mesh::face_materials

  MeshView() = default;
  MeshView(std::span<const double> p, std::span<const std::uint32_t> i) : positions(p), indices(i) {}
  MeshView(const Mesh& m)  // NOLINT: implicit on purpose
      : positions(m.positions), indices(m.indices), attributes(m.attributes), face_materials(m.face_materials) {}
  std::size_t vertex_count() const { return positions.size() / 3; }
  std::size_t face_count() const { return indices.size() / 3; }
};

/// Axis-aligned bounding box of the referenced and unreferenced vertices alike.
struct Box {
  double lo[3] = {0, 0, 0};
  double hi[3] = {0, 0, 0};
  double diagonal() const;
};
Box bounding_box(MeshView mesh);

}  // namespace qem
