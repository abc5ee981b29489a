// numpy arrays in and out of the library's flat arrays: the checks that name the bad argument,
// views without a copy where the layout allows, and outputs that hand their vectors to numpy.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "qem/mesh.h"

namespace qem::python {

namespace py = pybind11;

/// An (n, 3) array of coordinates as the library reads them: 3 doubles per vertex. `data` views
/// the caller's buffer when it is float64 and C-contiguous, else `copy` holds a converted copy.
struct Positions {
  py::object keep_alive;  ///< the array `data` points into
  std::vector<double> copy;
  std::span<const double> data;
};

/// An (m, 3) array of vertex indices as the library reads them: 3 uint32 per face. `data` views
/// the caller's buffer when it is int32/uint32 and C-contiguous, else `copy` holds a copy.
struct Indices {
  py::object keep_alive;
  std::vector<std::uint32_t> copy;
  std::span<const std::uint32_t> data;
};

/// Checks and converts; throws py::value_error naming `name` (shape, dtype, NaN or infinity).
Positions positions_from(py::handle obj, const char* name);
/// Checks and converts; every index must lie in [0, vertex_count): py::value_error naming `name`.
Indices indices_from(py::handle obj, const char* name, std::size_t vertex_count);

/// An (n, k) array of any numeric dtype as doubles (k = 1 for a 1-D array), for attributes.
std::vector<double> values_from(py::handle obj, const std::string& name, std::size_t rows, std::uint32_t& columns);

/// numpy arrays that take over the vector's buffer (no copy; freed when the array is).
py::array_t<double> take_positions(std::vector<double>&& v, std::size_t columns = 3);
/// Faces as int32 (the library's indices are below 2^31 whenever the vertex count is), taking the
/// buffer; int64 only for meshes of 2^31 vertices or more. `columns` = 3 for faces, 1 for maps.
py::array take_indices(std::vector<std::uint32_t>&& v, std::size_t columns, std::size_t vertex_count);
/// A map whose entries may be SimplifyResult::kUnmapped, which becomes -1 (int32, no copy).
py::array_t<std::int32_t> take_map(std::vector<std::uint32_t>&& v);

/// (vertices, faces) of a mesh-like Python object: a qem.Mesh / result (`.vertices`, `.faces`), an
/// Open3D TriangleMesh (`.vertices`, `.triangles`) or a (vertices, faces) tuple.
struct MeshArrays {
  Positions positions;
  Indices indices;
  MeshView view() const { return MeshView(positions.data, indices.data); }
};
MeshArrays mesh_from(py::handle obj, const char* name);

}  // namespace qem::python
