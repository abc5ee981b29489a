// `qem render`: draws a mesh to a PNG with the built-in software rasteriser (src/view/render.cpp),
// so pictures need no browser, no GPU and no display.
#include <cstdio>
#include <memory>
#include <string>

#include "cli_util.h"
#include "command.h"
#include "qem/io.h"
#include "view/png.h"
#include "view/render.h"

namespace qem::cli {

namespace {

struct RenderArgs {
  std::string input, output;
  view::RenderOptions options;
};

int run_render(const RenderArgs& a) {
  LoadOptions lo;
  lo.keep_vertex_properties = true;  // the `distance` heat map
  Mesh mesh = load_input(a.input, lo);
  view::Image image = view::render_mesh(mesh, a.options);
  view::save_png(a.output, image);
  std::printf("qem render: %s (%zu faces) -> %s (%dx%d)\n", a.input.c_str(), mesh.face_count(),
              a.output.c_str(), image.width, image.height);
  return 0;
}

const bool registered = register_command(81, [](CLI::App& app) -> std::function<int()> {
  auto args = std::make_shared<RenderArgs>();
  view::RenderOptions& o = args->options;
  CLI::App* cmd =
      app.add_subcommand("render", "Draw a mesh to a PNG picture (software rasteriser, no browser)");
  cmd->add_option("mesh", args->input, "Mesh file (OBJ, PLY, STL, OFF, glTF)")->required();
  cmd->add_option("out", args->output, "Output PNG file")->required();
  cmd->add_option("--width", o.width, "Picture width in pixels")
      ->capture_default_str()
      ->check(CLI::Range(1, 8192));
  cmd->add_option("--height", o.height, "Picture height in pixels")
      ->capture_default_str()
      ->check(CLI::Range(1, 8192));
  cmd->add_flag("--smooth", o.smooth, "Smooth shading (interpolated vertex normals) instead of flat");
  cmd->add_flag("--wireframe", o.wireframe, "Draw the triangle edges over the faces");
  cmd->add_flag("!--no-heatmap", o.heatmap, "Ignore a per-vertex `distance` property (no error heat map)");
  cmd->add_option("--yaw", o.yaw_degrees, "Camera azimuth around the vertical axis, degrees")
      ->capture_default_str();
  cmd->add_option("--pitch", o.pitch_degrees, "Camera elevation, degrees")
      ->capture_default_str()
      ->check(CLI::Range(-89.0, 89.0));
  cmd->add_option("--supersample", o.supersample, "Samples per pixel along each axis (anti-aliasing)")
      ->capture_default_str()
      ->check(CLI::Range(1, 4));
  return [args] { return run_render(*args); };
});

}  // namespace

}  // namespace qem::cli
