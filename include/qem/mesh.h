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

/// An indexed triangle mesh. `positions` holds x,y,z per vertex; `indices` holds 3 per triangle.
struct Mesh {
  std::vector<double> positions;
  std::vector<std::uint32_t> indices;
  /// Optional per-vertex scalars; readers fill them only when asked (LoadOptions).
  std::vector<VertexProperty> vertex_properties;

  std::size_t vertex_count() const { return positions.size() / 3; }
  std::size_t face_count() const { return indices.size() / 3; }
  /// The values of a named vertex property, or nullptr.
  const VertexProperty* find_property(const std::string& name) const;
};

/// A read-only view of caller-owned buffers: `positions` (3 per vertex), `indices` (3 per face).
struct MeshView {
  std::span<const double> positions;
  std::span<const std::uint32_t> indices;

  MeshView() = default;
  MeshView(std::span<const double> p, std::span<const std::uint32_t> i) : positions(p), indices(i) {}
  MeshView(const Mesh& m) : positions(m.positions), indices(m.indices) {}  // NOLINT: implicit on purpose
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
