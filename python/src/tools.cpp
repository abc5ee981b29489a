// qem._qem's file I/O, measure, cluster, info and lod: thin wrappers, each releasing the GIL
// while the library works.
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "arrays.h"
#include "bindings.h"
#include "qem/cluster.h"
#include "qem/io.h"
#include "qem/measure.h"
#include "qem/mesh_info.h"
#include "qem/progressive.h"
#include "qem/refit.h"
#include "refit/refit_after_simplify.h"

namespace qem::python {
namespace {

py::dict load(const std::string& path, const std::string& weld) {
  LoadOptions options;
  if (weld == "on") options.weld = Weld::On;
  else if (weld == "off") options.weld = Weld::Off;
  else if (weld != "auto") throw py::value_error("weld: expected 'auto', 'on' or 'off', got '" + weld + "'");
  LoadReport report;
  Mesh mesh;
  {
    py::gil_scoped_release nogil;
    mesh = load_mesh(path, options, &report);
  }
  py::dict out = mesh_to_python(std::move(mesh));
  out["double_precision"] = report.double_precision;
  out["warnings"] = report.warnings;
  return out;
}

void save(const std::string& path, py::handle vertices, py::handle faces, const py::list& attributes,
          bool binary, bool double_precision) {
  Positions p = positions_from(vertices, "mesh.vertices");
  Indices f = indices_from(faces, "mesh.faces", p.data.size() / 3);
  Mesh mesh;
  mesh.positions.assign(p.data.begin(), p.data.end());
  mesh.indices.assign(f.data.begin(), f.data.end());
  mesh.attributes = attributes_from_python(attributes, mesh.vertex_count());
  SaveOptions options;
  options.binary = binary;
  options.double_precision = double_precision;
  py::gil_scoped_release nogil;
  save_mesh(path, mesh, options);
}

py::dict measure(py::handle original, py::handle approx, std::size_t samples, std::uint64_t seed, unsigned threads,
                 const py::list& original_attributes, const py::list& approx_attributes) {
  MeshArrays a = mesh_from(original, "original"), b = mesh_from(approx, "approx");
  const std::vector<VertexAttribute> attributes_a = attributes_from_python(original_attributes, a.view().vertex_count());
  const std::vector<VertexAttribute> attributes_b = attributes_from_python(approx_attributes, b.view().vertex_count());
  MeshView view_a = a.view(), view_b = b.view();
  view_a.attributes = attributes_a, view_b.attributes = attributes_b;
  MeasureOptions options;
  options.samples = samples;
  options.seed = seed;
  options.threads = threads;
  MeasureResult r;
  {
    py::gil_scoped_release nogil;
    r = qem::measure(view_a, view_b, options);
  }
  py::dict out;
  out["E"] = r.E, out["E_rel"] = r.E_rel;
  out["rms"] = r.rms, out["rms_rel"] = r.rms_rel;
  out["mean"] = r.mean, out["mean_rel"] = r.mean_rel;
  out["hausdorff"] = r.hausdorff, out["hausdorff_rel"] = r.hausdorff_rel;
  out["h_original_to_approx"] = r.h_original_to_approx, out["h_approx_to_original"] = r.h_approx_to_original;
  out["bbox_diag"] = r.bbox_diag;
  out["area_original"] = r.area_original, out["area_approx"] = r.area_approx;
  out["samples_original"] = r.samples_original, out["samples_approx"] = r.samples_approx;
  // The attribute error (None where either mesh lacks the attribute) and the seam cracks.
  const auto optional = [](const std::optional<double>& x) { return x ? py::object(py::float_(*x)) : py::object(py::none()); };
  out["uv_rms"] = optional(r.uv_rms), out["normal_rms_deg"] = optional(r.normal_rms_deg);
  out["color_rms"] = optional(r.color_rms);
  out["seam_cracks"] = r.seam_cracks, out["cracks_in"] = r.cracks_in, out["cracks_out"] = r.cracks_out;
  return out;
}

py::dict cluster(py::handle vertices, py::handle faces, std::vector<int> grid, double cell, bool cell_relative,
                 const std::string& placement) {
  Positions p = positions_from(vertices, "vertices");
  Indices f = indices_from(faces, "faces", p.data.size() / 3);
  ClusterOptions options;
  if (!grid.empty()) {
    if (grid.size() != 3) throw py::value_error("grid: expected 3 cell counts (nx, ny, nz)");
    std::copy(grid.begin(), grid.end(), options.grid);
  }
  options.cell = cell;
  options.cell_relative = cell_relative;
  if (placement == "quadric") options.placement = ClusterPlacement::Quadric;
  else if (placement == "mean") options.placement = ClusterPlacement::Mean;
  else throw py::value_error("placement: expected 'quadric' or 'mean', got '" + placement + "'");
  Mesh out;
  {
    py::gil_scoped_release nogil;
    out = qem::cluster(MeshView(p.data, f.data), options);
  }
  return mesh_to_python(std::move(out));
}

py::dict info(py::handle vertices, py::handle faces) {
  Positions p = positions_from(vertices, "vertices");
  Indices f = indices_from(faces, "faces", p.data.size() / 3);
  MeshInfo i;
  {
    py::gil_scoped_release nogil;
    i = mesh_info(MeshView(p.data, f.data));
  }
  py::dict out;
  out["vertices"] = i.vertices, out["faces"] = i.faces, out["unreferenced_vertices"] = i.unreferenced_vertices;
  out["edges"] = i.edges, out["boundary_edges"] = i.boundary_edges, out["boundary_loops"] = i.boundary_loops;
  out["non_manifold_edges"] = i.non_manifold_edges, out["non_manifold_vertices"] = i.non_manifold_vertices;
  out["components"] = i.components, out["duplicate_faces"] = i.duplicate_faces;
  out["degenerate_faces"] = i.degenerate_faces, out["zero_area_faces"] = i.zero_area_faces;
  out["orientation_conflicts"] = i.orientation_conflicts, out["euler"] = i.euler, out["genus"] = i.genus;
  out["watertight"] = i.watertight(), out["manifold"] = i.manifold();
  out["bbox_min"] = std::vector<double>(i.box.lo, i.box.lo + 3);
  out["bbox_max"] = std::vector<double>(i.box.hi, i.box.hi + 3);
  out["diagonal"] = i.box.diagonal();
  return out;
}

// One recorded run to the smallest level, every level replayed from it, then each refitted as the
// options say: what `qem lod` does (cli/cmd_lod.cpp).
py::list lod(py::handle vertices, py::handle faces, SimplifyOptions options, const std::vector<std::size_t>& faces_targets,
             const std::vector<double>& ratios) {
  if (faces_targets.empty() == ratios.empty()) throw py::value_error("give the levels as either target_faces or ratios");
  for (double r : ratios)
    if (!(r >= 0 && r <= 1)) throw py::value_error("ratios: every ratio must be in [0, 1]");
  Positions p = positions_from(vertices, "vertices");
  Indices f = indices_from(faces, "faces", p.data.size() / 3);
  const SimplifyOptions refit_as = options;  // each level refitted as simplify would at its target
  options.refit_rounds = 0;
  if (!faces_targets.empty())
    options.target_faces = *std::min_element(faces_targets.begin(), faces_targets.end());
  else
    options.target_ratio = *std::min_element(ratios.begin(), ratios.end());
  // A level of 0 faces (or ratio 0) is the mesh as far as the checks allow, as in `qem lod`.
  options.as_far_as_possible = options.target_faces == 0 && options.target_ratio == 0;
  check_options(options);
  std::vector<ReplayLevel> levels;
  {
    py::gil_scoped_release nogil;
    const MeshView view(p.data, f.data);
    ContractionRecorder recorder;
    const SimplifyResult run = qem::simplify(view, options, &recorder);
    // As `qem lod`: a record replays one side of a sheet made two-sided by reversed copies of its
    // faces, so such an input's levels are runs of their own, which put the twins back.
    const bool own_runs = options.two_sided != TwoSided::None && run.dropped_duplicate_faces > 0;
    const Record record = own_runs ? Record{} : make_record(view, recorder.log);
    const std::size_t base_faces = own_runs ? run.input_faces : record.base.face_count();
    std::vector<std::size_t> targets = faces_targets;
    for (double r : ratios) targets.push_back(std::size_t(std::floor(r * double(base_faces))));
    std::sort(targets.begin(), targets.end(), std::greater<>());
    targets.erase(std::unique(targets.begin(), targets.end()), targets.end());
    if (own_runs) {
      for (std::size_t target : targets) {
        SimplifyOptions level = refit_as;
        level.target_ratio = 0, level.target_faces = target, level.as_far_as_possible = target == 0;
        SimplifyResult r = qem::simplify(view, level);
        levels.push_back({std::move(r.mesh), target, r.contractions, r.max_error});
      }
    } else {
      levels = replay_levels(record, targets);
      refit_levels(view, levels, refit_as, run.input_vertices);  // nothing without a refit
    }
  }
  py::list out;
  for (ReplayLevel& l : levels) {
    py::dict d = mesh_to_python(std::move(l.mesh));
    d["target_faces"] = l.target_faces;
    d["contractions"] = l.contractions;
    d["max_error"] = l.max_error;
    out.append(d);
  }
  return out;
}

}  // namespace

void bind_tools(py::module_& m) {
  m.def("load", &load, py::arg("path"), py::arg("weld"));
  m.def("save", &save, py::arg("path"), py::arg("vertices"), py::arg("faces"), py::arg("attributes"),
        py::arg("binary"), py::arg("double_precision"));
  m.def("measure", &measure, py::arg("original"), py::arg("approx"), py::arg("samples"), py::arg("seed"),
        py::arg("threads"), py::arg("original_attributes"), py::arg("approx_attributes"));
  m.def("cluster", &cluster, py::arg("vertices"), py::arg("faces"), py::arg("grid"), py::arg("cell"),
        py::arg("cell_relative"), py::arg("placement"));
  m.def("info", &info, py::arg("vertices"), py::arg("faces"));
  m.def("lod", &lod, py::arg("vertices"), py::arg("faces"), py::arg("options"), py::arg("target_faces"),
        py::arg("ratios"));
}

}  // namespace qem::python
