// qem._qem.simplify and the progressive record: the options, the observer that lets Python watch
// and cancel a run with the GIL released, and the result handed to numpy without copies.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <exception>
#include <optional>
#include <utility>

#include "arrays.h"
#include "bindings.h"
#include "qem/progressive.h"
#include "qem/simplify.h"

namespace qem::python {
namespace {

// The run's eyes from Python: records contractions when asked, and at each progress report takes
// the GIL to see Ctrl-C (the interpreter only notes the signal while C++ runs) and to call the
// user's callable. Either one cancels the run; a Python exception is kept to be raised after it.
class PythonObserver : public ContractionRecorder {
 public:
  PythonObserver(bool record, py::object progress) : record_(record), progress_(std::move(progress)) {}
  ~PythonObserver() override {
    py::gil_scoped_acquire gil;  // the callable's reference is dropped with the GIL held
    progress_ = py::object();
  }

  bool wants_contractions() const override { return record_; }
  void on_start(std::span<const std::uint32_t> faces) override {
    if (record_) ContractionRecorder::on_start(faces);
  }
  void on_contraction(const Contraction& c) override {
    if (record_) ContractionRecorder::on_contraction(c);
  }
  bool on_progress(double fraction) override {
    py::gil_scoped_acquire gil;  // worker threads may report too: the GIL serialises them
    if (error_) return false;
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (progress_.is_none()) return true;
      py::object go_on = progress_(fraction);
      // None (a callable that returns nothing) continues; anything false cancels.
      return go_on.is_none() || go_on.cast<bool>();
    } catch (...) {
      error_ = std::current_exception();
      return false;
    }
  }
  /// Raises what the callable or a signal handler raised, if anything (the GIL held).
  void rethrow() {
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }

 private:
  bool record_;
  py::object progress_;
  std::exception_ptr error_;
};

AttributeKind kind_named(const std::string& kind, const std::string& attribute) {
  static const std::pair<const char*, AttributeKind> kKinds[] = {
      {"normal", AttributeKind::Normal},         {"texcoord", AttributeKind::TexCoord},
      {"color", AttributeKind::Color},           {"joint_indices", AttributeKind::JointIndices},
      {"joint_weights", AttributeKind::JointWeights}, {"tangent", AttributeKind::Tangent},
      {"scalar", AttributeKind::Scalar}};
  for (const auto& [name, value] : kKinds)
    if (kind == name) return value;
  throw py::value_error("attributes['" + attribute + "']: unknown kind '" + kind +
                        "' (normal, texcoord, color, joint_indices, joint_weights, tangent, scalar)");
}

const char* kind_name(AttributeKind kind) {
  switch (kind) {
    case AttributeKind::Normal: return "normal";
    case AttributeKind::TexCoord: return "texcoord";
    case AttributeKind::Color: return "color";
    case AttributeKind::JointIndices: return "joint_indices";
    case AttributeKind::JointWeights: return "joint_weights";
    case AttributeKind::Tangent: return "tangent";
    case AttributeKind::Scalar: return "scalar";
  }
  return "scalar";
}

}  // namespace

py::dict attributes_to_python(std::vector<VertexAttribute>&& attributes) {
  py::dict out;
  for (VertexAttribute& a : attributes) {
    py::dict entry;
    entry["kind"] = kind_name(a.kind);
    entry["values"] = take_positions(std::move(a.values), a.components);
    out[py::str(a.name)] = entry;
  }
  return out;
}

std::vector<VertexAttribute> attributes_from_python(const py::list& attributes, std::size_t vertex_count) {
  std::vector<VertexAttribute> out;
  for (py::handle item : attributes) {
    auto t = item.cast<py::tuple>();  // (name, kind, values), built by qem/__init__.py
    VertexAttribute a;
    a.name = t[0].cast<std::string>();
    a.kind = kind_named(t[1].cast<std::string>(), a.name);
    a.values = values_from(t[2], "attributes['" + a.name + "']", vertex_count, a.components);
    out.push_back(std::move(a));
  }
  return out;
}

py::dict mesh_to_python(Mesh&& mesh) {
  py::dict out;
  const std::size_t n = mesh.vertex_count();
  out["vertices"] = take_positions(std::move(mesh.positions));
  out["faces"] = take_indices(std::move(mesh.indices), 3, n);
  out["attributes"] = attributes_to_python(std::move(mesh.attributes));
  return out;
}

void bind_simplify(py::module_& m) {
  py::class_<SimplifyOptions>(m, "SimplifyOptions", "qem::SimplifyOptions, field for field (see qem/simplify.h)")
      .def(py::init<>())
      .def_readwrite("target_faces", &SimplifyOptions::target_faces)
      .def_readwrite("target_ratio", &SimplifyOptions::target_ratio)
      .def_readwrite("target_vertices", &SimplifyOptions::target_vertices)
      .def_readwrite("as_far_as_possible", &SimplifyOptions::as_far_as_possible)
      .def_readwrite("keep_components", &SimplifyOptions::keep_components)
      .def_readwrite("prune_size", &SimplifyOptions::prune_size)
      .def_readwrite("prune_size_is_relative", &SimplifyOptions::prune_size_is_relative)
      .def_readwrite("max_error", &SimplifyOptions::max_error)
      .def_readwrite("max_error_is_relative", &SimplifyOptions::max_error_is_relative)
      .def_property("weighting", [](const SimplifyOptions& o) { return to_string(o.weighting); },
                    [](SimplifyOptions& o, const std::string& s) { o.weighting = enum_named<Weighting>("weighting", s); })
      .def_property("placement", [](const SimplifyOptions& o) { return to_string(o.placement); },
                    [](SimplifyOptions& o, const std::string& s) { o.placement = enum_named<Placement>("placement", s); })
      .def_property("scheme", [](const SimplifyOptions& o) { return to_string(o.scheme); },
                    [](SimplifyOptions& o, const std::string& s) { o.scheme = enum_named<Scheme>("scheme", s); })
      .def_property("inversion", [](const SimplifyOptions& o) { return to_string(o.inversion); },
                    [](SimplifyOptions& o, const std::string& s) {
                      o.inversion = enum_named<InversionPolicy>("inversion", s);
                    })
      .def_readwrite("threshold", &SimplifyOptions::threshold)
      .def_readwrite("threshold_is_relative", &SimplifyOptions::threshold_is_relative)
      .def_readwrite("boundary_weight", &SimplifyOptions::boundary_weight)
      .def_readwrite("lock_border", &SimplifyOptions::lock_border)
      .def_readwrite("exact_border", &SimplifyOptions::exact_border)
      .def_readwrite("max_distance", &SimplifyOptions::max_distance)
      .def_readwrite("max_distance_is_relative", &SimplifyOptions::max_distance_is_relative)
      .def_readwrite("max_normal_turn_degrees", &SimplifyOptions::max_normal_turn_degrees)
      .def_readwrite("preserve_topology", &SimplifyOptions::preserve_topology)
      .def_readwrite("greedy_below_faces", &SimplifyOptions::greedy_below_faces)
      .def_readwrite("forget", &SimplifyOptions::forget)
      .def_readwrite("forget_attributes", &SimplifyOptions::forget_attributes)
      .def_readwrite("threads", &SimplifyOptions::threads)
      .def_readwrite("refit_rounds", &SimplifyOptions::refit_rounds)
      .def_readwrite("refit_points_per_vertex", &SimplifyOptions::refit_points_per_vertex)
      .def_readwrite("refit_by_reduction", &SimplifyOptions::refit_by_reduction)
      .def_readwrite("far_repair", &SimplifyOptions::far_repair)
      .def_property("two_sided", [](const SimplifyOptions& o) { return to_string(o.two_sided); },
                    [](SimplifyOptions& o, const std::string& s) { o.two_sided = enum_named<TwoSided>("two_sided", s); })
      .def_readwrite("fit_attributes", &SimplifyOptions::fit_attributes)
      .def_property("seams", [](const SimplifyOptions& o) { return to_string(o.seams); },
                    [](SimplifyOptions& o, const std::string& s) { o.seams = enum_named<SeamMode>("seams", s); })
      .def_readwrite("map_input_vertices", &SimplifyOptions::map_input_vertices)
      .def_property(
          "attribute_weights",
          [](const SimplifyOptions& o) {
            const AttributeWeights& w = o.attribute_weights;
            return py::dict(py::arg("normal") = w.normal, py::arg("uv") = w.tex_coord, py::arg("color") = w.color,
                            py::arg("scalar") = w.scalar, py::arg("normal_per_spacing") = w.normal_per_spacing,
                            py::arg("color_per_spacing") = w.color_per_spacing);
          },
          [](SimplifyOptions& o, const py::dict& weights) {
            // A normal or colour weight given is the weight, unless its spacing factor is given with
            // it (AttributeWeights::normal_per_spacing, color_per_spacing).
            if (weights.contains("normal") && !weights.contains("normal_per_spacing"))
              o.attribute_weights.normal_per_spacing = 0;
            if (weights.contains("color") && !weights.contains("color_per_spacing"))
              o.attribute_weights.color_per_spacing = 0;
            for (auto [key, value] : weights) {
              const std::string kind = py::str(key);
              double* w = kind == "normal" ? &o.attribute_weights.normal
                          : kind == "uv"   ? &o.attribute_weights.tex_coord
                          : kind == "color" ? &o.attribute_weights.color
                          : kind == "scalar" ? &o.attribute_weights.scalar
                          : kind == "normal_per_spacing" ? &o.attribute_weights.normal_per_spacing
                          : kind == "color_per_spacing" ? &o.attribute_weights.color_per_spacing
                                             : nullptr;
              if (!w)
                throw py::value_error("attribute_weights: unknown kind '" + kind +
                                      "' (normal, uv, color, scalar, normal_per_spacing, color_per_spacing)");
              const double x = value.cast<double>();
              if (!(x >= 0) || !std::isfinite(x))
                throw py::value_error("attribute_weights['" + kind + "']: expected a finite weight >= 0");
              *w = x;
            }
          })
      .def("check", [](const SimplifyOptions& o) { check_options(o); }, "Raises qem.Error for an option out of range");

  m.def("option_names", [](const std::string& option) -> std::vector<std::string> {
    if (option == "weighting") return option_names<Weighting>();
    if (option == "placement") return option_names<Placement>();
    if (option == "scheme") return option_names<Scheme>();
    if (option == "inversion") return option_names<InversionPolicy>();
    if (option == "two_sided") return option_names<TwoSided>();
    if (option == "seams") return option_names<SeamMode>();
    throw py::value_error("option: expected weighting, placement, scheme, inversion, two_sided or seams, got '" + option + "'");
  });

  py::class_<Record>(m, "Record", "qem::Record: the base mesh and the contraction sequence of one run")
      .def("__len__", &Record::size)
      .def_property_readonly("final_faces", &Record::final_faces)
      .def_property_readonly("base_faces", [](const Record& r) { return r.base.face_count(); })
      .def_property_readonly("base_vertices", [](const Record& r) { return r.base.vertex_count(); })
      .def("replay",
           [](const Record& r, std::size_t target_faces) {
             Mesh mesh;
             {
               py::gil_scoped_release nogil;
               mesh = replay(r, target_faces);
             }
             return mesh_to_python(std::move(mesh));
           },
           py::arg("target_faces"))
      .def("save", [](const Record& r, const std::string& path) { write_record(path, r); }, py::arg("path"))
      .def_static("load", [](const std::string& path) { return read_record(path); }, py::arg("path"))
      .def("to_bytes", [](const Record& r) { return py::bytes(serialize_record(r)); })
      .def_static("from_bytes", [](const py::bytes& b) { return parse_record(std::string(b), "record"); });

  m.def(
      "simplify",
      [](py::handle vertices, py::handle faces, SimplifyOptions options, const py::list& attributes,
         bool record, py::object progress, py::object vertex_lock) {
        check_options(options);  // before any work on the arrays: a slip in the options is said at once
        Positions p = positions_from(vertices, "vertices");
        Indices f = indices_from(faces, "faces", p.data.size() / 3);
        // vertex_lock: any array of n truth values (bool or integers), held here for the call.
        std::vector<std::uint8_t> lock;
        if (!vertex_lock.is_none()) {
          const auto values = py::array_t<std::uint8_t, py::array::forcecast>::ensure(vertex_lock);
          if (!values || values.ndim() != 1 || std::size_t(values.shape(0)) != p.data.size() / 3)
            throw py::value_error("vertex_lock: expected " + std::to_string(p.data.size() / 3) +
                                  " truth values, one per vertex");
          lock.assign(values.data(), values.data() + values.shape(0));
          options.vertex_lock = lock;
        }
        std::vector<VertexAttribute> attrs = attributes_from_python(attributes, p.data.size() / 3);
        PythonObserver observer(record, std::move(progress));
        SimplifyResult r;
        {
          py::gil_scoped_release nogil;
          if (!record && !p.copy.empty() && !f.copy.empty()) {
            // Both arrays were converted: hand the copies over, so the simplifier frees the faces
            // as soon as it holds its own (lower peak memory, as the CLI).
            Mesh mesh;
            mesh.positions = std::move(p.copy);
            mesh.indices = std::move(f.copy);
            mesh.attributes = std::move(attrs);
            r = qem::simplify(std::move(mesh), options, &observer);
          } else {
            MeshView view(p.data, f.data);
            view.attributes = attrs;
            r = qem::simplify(view, options, &observer);
          }
        }
        observer.rethrow();
        py::dict out = mesh_to_python(std::move(r.mesh));
        out["max_error"] = r.max_error;
        out["max_error_relative"] = r.max_error_relative;
        out["stop_reason"] = to_string(r.stop_reason);
        out["stop_detail"] = r.stop_detail;
        out["input_faces"] = r.input_faces;
        out["input_vertices"] = r.input_vertices;
        out["contractions"] = r.contractions;
        out["rejected_component"] = r.rejected_component;
        out["input_components"] = r.input_components;
        out["output_components"] = r.output_components;
        out["pruned_components"] = r.pruned_components;
        out["output_to_input_distance"] = r.output_to_input_distance;
        out["output_to_input_distance_relative"] = r.output_to_input_distance_relative;
        out["rejected_distance"] = r.rejected_distance;
        out["refit_rounds"] = r.refit_rounds;
        out["refit_rms_before"] = r.refit_rms_before;
        out["refit_rms_after"] = r.refit_rms_after;
        out["edge_flips"] = r.edge_flips;
        out["vertex_moves"] = r.vertex_moves;
        out["vertex_relocations"] = r.vertex_relocations;
        out["dropped_degenerate_faces"] = r.dropped_degenerate_faces;
        out["dropped_duplicate_faces"] = r.dropped_duplicate_faces;
        out["twin_faces"] = r.twin_faces;
        out["normal_weight"] = r.normal_weight;
        out["color_weight"] = r.color_weight;
        out["vertex_source"] = take_indices(std::move(r.vertex_source), 1, p.data.size() / 3);
        out["face_source"] = take_indices(std::move(r.face_source), 1, f.data.size() / 3);
        out["output_vertex_of_input"] =
            options.map_input_vertices ? py::object(take_map(std::move(r.output_vertex_of_input))) : py::none();
        if (record) {
          MeshView view(p.data, f.data);
          out["record"] = make_record(view, observer.log);
        } else {
          out["record"] = py::none();
        }
        return out;
      },
      py::arg("vertices"), py::arg("faces"), py::arg("options"), py::arg("attributes"), py::arg("record"),
      py::arg("progress"), py::arg("vertex_lock") = py::none());
}

}  // namespace qem::python
