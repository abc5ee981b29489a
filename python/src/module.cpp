// The compiled part of the Python package: `qem._qem`. The package's own qem/__init__.py gives it
// its keyword-only API and documentation; this module converts arrays and runs the library.
#include "bindings.h"
#include "qem/error.h"
#include "qem/simplify.h"

PYBIND11_MODULE(_qem, m) {
  namespace py = pybind11;
  m.doc() = "qem's compiled core; use the package `qem`, not this module";
  // Every user-caused failure of the library is a qem::Error: a ValueError in Python, so callers
  // that catch bad input generally (ValueError) catch it too.
  py::register_exception<qem::Error>(m, "Error", PyExc_ValueError);
  m.attr("kUnmapped") = -1;
  m.attr("RECOMMENDED_FORGET") = qem::kRecommendedForget;  // the defaults of qem/__init__.py
  qem::python::bind_simplify(m);
  qem::python::bind_tools(m);
  qem::python::bind_gltf(m);
}
