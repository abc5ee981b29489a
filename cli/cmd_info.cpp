// `qem info MESH [--json]`: what the loader did and the mesh's topological
// facts (mesh_info.h), so users can see why a simplification behaves as it does
// (boundaries, non-manifold parts, flips).
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "cli_util.h"
#include "command.h"
#include "qem/io.h"
#include "qem/mesh_info.h"

namespace qem::cli {
namespace {

const char* format_name(FileFormat f) {
  switch (f) {
    case FileFormat::Obj:
      return "obj";
    case FileFormat::Ply:
      return "ply";
    case FileFormat::Stl:
      return "stl";
    case FileFormat::Off:
      return "off";
    case FileFormat::Gltf:
      return "gltf";
    case FileFormat::Auto:
      break;
  }
  return "unknown";
}

const char* kind_name(AttributeKind k) {
  switch (k) {
    case AttributeKind::Normal:
      return "normal";
    case AttributeKind::TexCoord:
      return "texcoord";
    case AttributeKind::Color:
      return "color";
    case AttributeKind::JointIndices:
      return "joint_indices";
    case AttributeKind::JointWeights:
      return "joint_weights";
    case AttributeKind::Tangent:
      return "tangent";
    case AttributeKind::Scalar:
      break;
  }
  return "scalar";
}

/// Shortest text that reads back to the same double (%.17g is exact but noisy).
std::string number(double x) {
  char buf[32];
  for (int precision = 6; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

void print_json(const std::string& path, const LoadReport& r, const Mesh& mesh, const MeshInfo& m,
                std::size_t wedges) {
  auto z = [](std::size_t v) { return std::to_string(v); };
  std::string s = "{\"file\":" + json_string(path);
  s += ",\"format\":\"" + std::string(format_name(r.format)) + "\"";
  s += ",\"binary\":" + std::string(r.binary ? "true" : "false");
  s += ",\"polygons_triangulated\":" + z(r.polygons_triangulated);
  s += ",\"vertices_welded\":" + z(r.vertices_welded);
  s += ",\"warnings\":[";
  for (std::size_t i = 0; i < r.warnings.size(); ++i) s += (i ? "," : "") + json_string(r.warnings[i]);
  s += "]";
  s += ",\"vertices\":" + z(m.vertices) + ",\"faces\":" + z(m.faces);
  s += ",\"unreferenced_vertices\":" + z(m.unreferenced_vertices);
  s += ",\"edges\":" + z(m.edges) + ",\"boundary_edges\":" + z(m.boundary_edges);
  s += ",\"boundary_loops\":" + z(m.boundary_loops);
  s += ",\"non_manifold_edges\":" + z(m.non_manifold_edges);
  s += ",\"non_manifold_vertices\":" + z(m.non_manifold_vertices);
  s += ",\"components\":" + z(m.components);
  s += ",\"duplicate_faces\":" + z(m.duplicate_faces);
  s += ",\"degenerate_faces\":" + z(m.degenerate_faces);
  s += ",\"zero_area_faces\":" + z(m.zero_area_faces);
  s += ",\"orientation_conflicts\":" + z(m.orientation_conflicts);
  s += ",\"watertight\":" + std::string(m.watertight() ? "true" : "false");
  s += ",\"manifold\":" + std::string(m.manifold() ? "true" : "false");
  s += ",\"euler\":" + std::to_string(m.euler);
  s += ",\"genus\":" + (m.genus < 0 ? std::string("null") : std::to_string(m.genus));
  s += ",\"attributes\":[";
  for (std::size_t i = 0; i < mesh.attributes.size(); ++i) {
    const VertexAttribute& a = mesh.attributes[i];
    s += std::string(i ? "," : "") + "{\"name\":" + json_string(a.name) + ",\"kind\":\"" + kind_name(a.kind) +
         "\",\"components\":" + std::to_string(a.components) + "}";
  }
  s += "],\"wedges\":" + z(wedges) + ",\"seam_vertices\":" + z(m.seam_vertices);
  s += ",\"materials\":" + z(m.materials) + ",\"material_names\":[";
  for (std::size_t i = 0; i < mesh.material_names.size(); ++i)
    s += (i ? "," : "") + json_string(mesh.material_names[i]);
  s += "],\"material_library\":" + json_string(mesh.material_library);
  s += ",\"bbox\":[";
  for (int k = 0; k < 6; ++k) s += (k ? "," : "") + number(k < 3 ? m.box.lo[k] : m.box.hi[k - 3]);
  s += "],\"bbox_diagonal\":" + number(m.box.diagonal()) + "}";
  std::printf("%s\n", s.c_str());
}

void print_report(const std::string& path, const LoadReport& r, const Mesh& mesh, const MeshInfo& m,
                  std::size_t wedges) {
  auto yes = [](bool b) { return b ? "yes" : "no"; };
  std::printf("%s\n", path.c_str());
  std::printf("  loaded as              %s%s\n", format_name(r.format),
              r.format == FileFormat::Gltf ? (r.binary ? " (binary .glb)" : " (JSON .gltf)")
              : r.format == FileFormat::Ply || r.format == FileFormat::Stl
                  ? (r.binary ? " (binary)" : " (ascii)")
                  : "");
  std::printf("  polygons triangulated  %zu\n", r.polygons_triangulated);
  std::printf("  vertices welded        %zu\n", r.vertices_welded);
  // What the reader skipped belongs with what it did: the report is where `info` users look.
  for (const std::string& w : r.warnings) std::printf("  warning                %s\n", w.c_str());
  std::printf("  vertices               %zu (%zu unreferenced)\n", m.vertices, m.unreferenced_vertices);
  std::printf("  faces                  %zu\n", m.faces);
  std::printf("  edges                  %zu\n", m.edges);
  std::printf("  boundary               %zu edges in %zu loops\n", m.boundary_edges, m.boundary_loops);
  std::printf("  non-manifold           %zu edges, %zu vertices\n", m.non_manifold_edges,
              m.non_manifold_vertices);
  std::printf("  components             %zu\n", m.components);
  std::printf("  duplicate faces        %zu\n", m.duplicate_faces);
  std::printf(
      "  degenerate faces       %zu (%zu with zero area, %zu with a "
      "repeated index)\n",
      m.degenerate_faces, m.zero_area_faces, m.degenerate_faces - m.zero_area_faces);
  std::printf("  orientation conflicts  %zu\n", m.orientation_conflicts);
  std::printf("  watertight / manifold  %s / %s\n", yes(m.watertight()), yes(m.manifold()));
  std::printf("  euler characteristic   %lld\n", m.euler);
  if (m.genus >= 0)
    std::printf("  genus                  %lld\n", m.genus);
  else
    std::printf("  genus                  - (not a closed oriented manifold)\n");
  if (mesh.attributes.empty()) std::printf("  attributes             none\n");
  for (const VertexAttribute& a : mesh.attributes)
    std::printf("  attribute              %s (%s, %u components)\n", a.name.c_str(), kind_name(a.kind),
                a.components);
  if (wedges != m.vertices)
    std::printf(
        "  wedges                 %zu (vertices with their attributes; the counts above are of positions)\n",
        wedges);
  std::printf("  seam vertices          %zu (positions held by more than one vertex)\n", m.seam_vertices);
  std::printf("  materials              %zu", m.materials);
  if (!mesh.material_library.empty()) std::printf(" (library %s)", mesh.material_library.c_str());
  std::printf("\n");
  std::printf("  bounding box           [%s, %s, %s] - [%s, %s, %s]\n", number(m.box.lo[0]).c_str(),
              number(m.box.lo[1]).c_str(), number(m.box.lo[2]).c_str(), number(m.box.hi[0]).c_str(),
              number(m.box.hi[1]).c_str(), number(m.box.hi[2]).c_str());
  std::printf("  diagonal               %s\n", number(m.box.diagonal()).c_str());
}

struct InfoArgs {
  std::string path;
  bool json = false;
  std::string weld = "auto";
};

[[maybe_unused]] const bool registered = register_command(40, [](CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* sub = app.add_subcommand("info", "Print a mesh's counts and topological defects");
  sub->add_option("mesh", args->path, "Mesh file (OBJ, PLY, STL, OFF, or glTF .gltf/.glb: the scene merged)")
      ->required();
  sub->add_flag("--json", args->json, "Print one JSON object on one line instead of the report");
  sub->add_option("--weld", args->weld, "Merge exactly coincident vertices on load: auto (STL only), on, off")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  return [args]() {
    LoadOptions options;
    options.weld = args->weld == "on" ? Weld::On : args->weld == "off" ? Weld::Off : Weld::Auto;
    LoadReport report;
    Mesh mesh = load_mesh(args->path, options, &report);
    MeshInfo info = mesh_info(mesh);
    const std::size_t wedges = mesh.vertex_count();
    if (report.format == FileFormat::Obj && info.seam_vertices > 0 && !mesh.attributes.empty()) {
      // The topology of an OBJ is that of its `v` lines: the wedges its vt/vn corners split a
      // position into would count every UV seam as a border (the catalogue counts `v` lines too).
      LoadOptions positions_only = options;
      positions_only.read_attributes = false;
      MeshInfo topology = mesh_info(load_mesh(args->path, positions_only));
      topology.seam_vertices = info.seam_vertices;
      topology.materials = info.materials;
      info = topology;
    }
    if (args->json)
      print_json(args->path, report, mesh, info, wedges);
    else
      print_report(args->path, report, mesh, info, wedges);
    return 0;
  };
});

}  // namespace
}  // namespace qem::cli
