// qem._qem's glTF document: simplify_document on a file, the document kept (materials, textures,
// nodes, skins, animations, extensions), written to another; the GIL released while it works.
#include <pybind11/stl.h>

#include <string>

#include "bindings.h"
#include "qem/gltf.h"
#include "qem/gltf_simplify.h"

namespace qem::python {
namespace {

py::dict simplify_gltf(const std::string& input, const std::string& output, const SimplifyOptions& options,
                       bool per_mesh, unsigned threads) {
  GltfSimplifyReport report;
  std::vector<GltfPrimitiveInfo> primitives;
  std::vector<std::string> notes;
  {
    py::gil_scoped_release nogil;
    GltfDocument doc = GltfDocument::load(input);
    GltfSimplifyOptions gltf_options;
    gltf_options.per_primitive = per_mesh;
    gltf_options.threads = threads;
    report = simplify_document(doc, options, gltf_options);
    doc.save(output);  // written to a temporary file and renamed: a failed run leaves no output
    primitives = doc.primitives();
    notes = doc.notes();
  }
  py::list each;
  for (const GltfPrimitiveOutcome& o : report.primitives) {
    const GltfPrimitiveInfo& p = primitives[o.primitive];
    py::dict d;
    d["mesh"] = p.mesh;
    d["primitive"] = p.primitive;
    d["status"] = to_string(o.status);
    d["faces_in"] = o.faces_in;
    d["faces_out"] = o.faces_out;
    d["world_scale"] = o.world_scale;
    d["world_error"] = o.world_error;
    d["stop_reason"] = o.status == GltfPrimitiveOutcome::Status::Simplified ? to_string(o.stop_reason) : "";
    d["note"] = o.note;
    each.append(d);
  }
  py::dict out;
  out["faces_in"] = report.faces_in;
  out["faces_out"] = report.faces_out;
  out["target_faces"] = report.target_faces;
  out["world_threshold"] = report.world_threshold;
  out["max_world_error"] = report.max_world_error;
  out["simplified"] = report.simplified;
  out["unchanged"] = report.unchanged;
  out["kept"] = report.kept;
  out["primitives"] = each;
  out["notes"] = notes;
  return out;
}

}  // namespace

void bind_gltf(py::module_& m) {
  m.def("simplify_gltf", &simplify_gltf, py::arg("input"), py::arg("output"), py::arg("options"),
        py::arg("per_mesh"), py::arg("threads"));
}

}  // namespace qem::python
