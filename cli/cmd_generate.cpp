// `qem generate KIND OUTPUT`: synthetic meshes of any size, so that the README's first command
// (and a benchmark) needs no downloaded model. A .ply is streamed to disk (bounded memory, up to
// a billion faces and more); other formats are built in memory.
#include <cstdio>
#include <string>

#include "command.h"
#include "outofcore/mesh_generator.h"
#include "qem/error.h"
#include "qem/io.h"

namespace qem::cli {
namespace {

struct GenerateArgs {
  std::string kind = "sphere", output;
  std::size_t faces = 100000;
};

const bool registered = register_command(5, [](CLI::App& app) {
  auto args = std::make_shared<GenerateArgs>();
  CLI::App* sub = app.add_subcommand("generate", "Write a synthetic test mesh (bumpy sphere or torus)");
  sub->add_option("kind", args->kind, "sphere (closed, bumpy icosphere) or torus")
      ->required()
      ->check(CLI::IsMember({"sphere", "torus"}));
  sub->add_option("output", args->output, "Output mesh (.obj .ply .stl .off)")->required();
  sub->add_option("--faces", args->faces,
                  "At least this many faces (sphere: next 20 * 4^level). A .ply is streamed to disk in "
                  "bounded memory (up to 1342177280 sphere or 2000000000 torus faces); other formats "
                  "are built in memory (up to 200000000)")
      ->capture_default_str();
  return [args] {
    const bool sphere = args->kind == "sphere";
    if (format_from_extension(args->output) == FileFormat::Ply) {
      const outofcore::GeneratedCounts n = sphere
                                               ? outofcore::write_bumpy_sphere_ply(args->output, args->faces)
                                               : outofcore::write_torus_ply(args->output, args->faces);
      std::fprintf(stderr, "qem: wrote %s: %llu vertices, %llu faces\n", args->output.c_str(),
                   static_cast<unsigned long long>(n.vertices), static_cast<unsigned long long>(n.faces));
      return 0;
    }
    if (args->faces > 200000000)
      throw Error(
          "--faces is too large for a mesh built in memory (at most 200000000); write a .ply, "
          "which is streamed");
    Mesh m = sphere ? outofcore::bumpy_sphere(args->faces) : outofcore::torus(args->faces);
    save_mesh(args->output, m);
    std::fprintf(stderr, "qem: wrote %s: %zu vertices, %zu faces\n", args->output.c_str(), m.vertex_count(),
                 m.face_count());
    return 0;
  };
});

}  // namespace
}  // namespace qem::cli
