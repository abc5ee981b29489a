// `qem render`: a software rasteriser that draws a mesh to an RGB image the way the viewer page
// shows it (same default view, shading and heat map colours), with no browser or GPU, so it works
// on a headless machine and in ctest. A z-buffer over supersampled pixels, Lambert shading with a
// camera-attached light, optional wireframe from screen-space edge distances.
#pragma once

#include <array>

#include "qem/mesh.h"
#include "view/png.h"

namespace qem::view {

struct RenderOptions {
  int width = 800, height = 600;
  bool smooth = false;        ///< per-vertex (area-weighted) normals instead of face normals
  bool wireframe = false;     ///< dark 1-pixel edges over the shaded faces
  bool heatmap = true;        ///< colour by the `distance` vertex property when the mesh has one
  double yaw_degrees = 30;    ///< camera azimuth around the vertical (y) axis; 0 looks along -z
  double pitch_degrees = 20;  ///< camera elevation above the horizontal plane
  int supersample = 3;        ///< samples per pixel along each axis (anti-aliasing)
};

/// Draws the mesh. Deterministic: the same mesh and options give the same pixels.
/// Throws qem::Error for an image size outside 1..8192 or out-of-range indices.
Image render_mesh(const Mesh& mesh, const RenderOptions& options = {});

/// The heat map colour (RGB in 0..1) for t in 0..1; the viewer page uses the same stops (viridis).
std::array<double, 3> heat_color(double t);

}  // namespace qem::view
