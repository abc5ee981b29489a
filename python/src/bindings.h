// What the binding files share: one registration function per concept, the enum names, and the
// conversions of meshes and attributes to Python.
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "qem/mesh.h"
#include "qem/simplify.h"

namespace qem::python {

namespace py = pybind11;

void bind_simplify(py::module_& m);  // SimplifyOptions, simplify, Record
void bind_tools(py::module_& m);     // load, save, measure, cluster, info, lod
void bind_gltf(py::module_& m);      // simplify_gltf

/// The value of an option enum called `name`, or ValueError listing the choices.
template <class Enum>
Enum enum_named(const char* option, const std::string& name) {
  Enum value{};
  if (from_string(name, value)) return value;
  std::string choices;
  for (const std::string& n : option_names<Enum>()) choices += (choices.empty() ? "" : ", ") + n;
  throw py::value_error(std::string(option) + ": unknown value '" + name + "' (one of " + choices + ")");
}

/// {"vertices", "faces", "attributes"}: the mesh's arrays handed to numpy without copies.
py::dict mesh_to_python(Mesh&& mesh);
/// {name: {"kind", "values"}}.
py::dict attributes_to_python(std::vector<VertexAttribute>&& attributes);
/// From the [(name, kind, values)] list that qem/__init__.py builds; ValueError naming the attribute.
std::vector<VertexAttribute> attributes_from_python(const py::list& attributes, std::size_t vertex_count);

}  // namespace qem::python
