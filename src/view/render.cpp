// The software rasteriser of `qem render` (render.h).
#include "view/render.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "geometry/box.h"
#include "geometry/vec3.h"
#include "qem/error.h"
#include "view/scene.h"

namespace qem::view {

std::array<double, 3> heat_color(double t) {
  // Viridis sampled at 0, .25, .5, .75, 1: perceptually uniform and readable in grey scale.
  static constexpr double stops[5][3] = {{0.267, 0.005, 0.329},
                                         {0.229, 0.322, 0.546},
                                         {0.128, 0.567, 0.551},
                                         {0.369, 0.789, 0.383},
                                         {0.993, 0.906, 0.144}};
  if (!(t > 0)) t = 0;
  if (t > 1) t = 1;
  double x = t * 4;
  int i = std::min(3, static_cast<int>(x));
  double f = x - i;
  return {stops[i][0] + f * (stops[i + 1][0] - stops[i][0]),
          stops[i][1] + f * (stops[i + 1][1] - stops[i][1]),
          stops[i][2] + f * (stops[i + 1][2] - stops[i][2])};
}

namespace {

// The page's look: light grey-blue surface on a light background.
constexpr double kBase[3] = {0.72, 0.76, 0.82};
constexpr double kBackground[3] = {0.96, 0.96, 0.96};
constexpr double kWire[3] = {0.10, 0.10, 0.12};
// Vertical field of view, as the page's PerspectiveCamera.
constexpr double kFovDegrees = 35;

}  // namespace

Image render_mesh(const Mesh& mesh, const RenderOptions& o) {
  if (o.width < 1 || o.height < 1 || o.width > 8192 || o.height > 8192)
    throw Error("render: the picture size must be 1..8192 pixels each way, got " + std::to_string(o.width) +
                "x" + std::to_string(o.height));
  const int ss = std::clamp(o.supersample, 1, 4);
  const int W = o.width * ss, H = o.height * ss;
  const std::size_t nv = mesh.vertex_count(), nf = mesh.face_count();
  for (std::uint32_t i : mesh.indices)
    if (i >= nv) throw Error("render: face index " + std::to_string(i) + " out of range");

  // Frame the bounding sphere of the box, as the page does (scene.cpp's centre and radius).
  Box box = bounding_box(mesh);
  Vec3 center = box_center(box);
  double radius = 0.5 * box.diagonal();
  if (!(radius > 0)) radius = 1;
  const double deg = std::numbers::pi / 180;
  const double half_fov = 0.5 * kFovDegrees * deg;
  // Fit the sphere in the narrower of the two field-of-view directions.
  double aspect = static_cast<double>(W) / H;
  double half_fov_min = aspect >= 1 ? half_fov : std::atan(std::tan(half_fov) * aspect);
  double dist = radius / std::sin(half_fov_min) * 1.05;
  double yaw = o.yaw_degrees * deg, pitch = o.pitch_degrees * deg;
  Vec3 eye =
      center + Vec3{std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw)} * dist;
  Vec3 fwd = normalized(center - eye);
  Vec3 right = normalized(cross(fwd, Vec3{0, 1, 0}));
  if (dot(right, right) == 0) right = {1, 0, 0};  // looking straight down the y axis
  Vec3 up = cross(right, fwd);
  double focal = 0.5 * H / std::tan(half_fov);
  // A key light over the viewer's left shoulder, moving with the camera (as in the page).
  Vec3 light = normalized(fwd * -1.0 + up * 0.6 + right * -0.35);

  // Project every vertex once: screen x, y and camera depth.
  std::vector<double> sx(nv), sy(nv), sz(nv);
  for (std::size_t v = 0; v < nv; ++v) {
    Vec3 p = Vec3{mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]} - eye;
    double z = std::max(dot(p, fwd), 1e-9 * radius);
    sx[v] = 0.5 * W + dot(p, right) / z * focal;
    sy[v] = 0.5 * H - dot(p, up) / z * focal;
    sz[v] = z;
  }

  // Per-vertex colour: the heat map over the property's range, else the base colour.
  std::vector<float> color(3 * nv);
  const VertexProperty* heat = o.heatmap ? mesh.find_property(kHeatProperty) : nullptr;
  if (heat && heat->values.size() != nv) heat = nullptr;
  double hlo = INFINITY, hhi = -INFINITY;
  if (heat)
    for (double d : heat->values)
      if (std::isfinite(d)) hlo = std::min(hlo, d), hhi = std::max(hhi, d);
  for (std::size_t v = 0; v < nv; ++v) {
    if (heat) {
      double d = heat->values[v];
      auto c = heat_color(hhi > hlo && std::isfinite(d) ? (d - hlo) / (hhi - hlo) : 0);
      for (int k = 0; k < 3; ++k) color[3 * v + k] = static_cast<float>(c[k]);
    } else {
      for (int k = 0; k < 3; ++k) color[3 * v + k] = static_cast<float>(kBase[k]);
    }
  }

  // Face normals (unnormalised: length = 2 * area) and, for smooth shading, their sums per vertex.
  std::vector<Vec3> face_n(nf);
  std::vector<Vec3> vert_n(o.smooth ? nv : 0, Vec3{0, 0, 0});
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t* t = &mesh.indices[3 * f];
    Vec3 a{mesh.positions[3 * t[0]], mesh.positions[3 * t[0] + 1], mesh.positions[3 * t[0] + 2]};
    Vec3 b{mesh.positions[3 * t[1]], mesh.positions[3 * t[1] + 1], mesh.positions[3 * t[1] + 2]};
    Vec3 c{mesh.positions[3 * t[2]], mesh.positions[3 * t[2] + 1], mesh.positions[3 * t[2] + 2]};
    face_n[f] = cross(b - a, c - a);
    if (o.smooth)
      for (int k = 0; k < 3; ++k) vert_n[t[k]] = vert_n[t[k]] + face_n[f];
  }
  for (auto& n : face_n) n = normalized(n);
  for (auto& n : vert_n) n = normalized(n);

  std::vector<float> rgb(static_cast<std::size_t>(W) * H * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<float>(kBackground[i % 3]);
  // Depth as 1/z: linear in screen space, so it interpolates exactly across a triangle.
  std::vector<double> inv_z(static_cast<std::size_t>(W) * H, 0.0);
  const double wire_px = 0.6 * ss;

  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t* t = &mesh.indices[3 * f];
    double x0 = sx[t[0]], y0 = sy[t[0]], x1 = sx[t[1]], y1 = sy[t[1]], x2 = sx[t[2]], y2 = sy[t[2]];
    double area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
    if (area == 0 || !std::isfinite(area)) continue;
    int xmin = std::max(0, static_cast<int>(std::floor(std::min({x0, x1, x2}))));
    int xmax = std::min(W - 1, static_cast<int>(std::ceil(std::max({x0, x1, x2}))));
    int ymin = std::max(0, static_cast<int>(std::floor(std::min({y0, y1, y2}))));
    int ymax = std::min(H - 1, static_cast<int>(std::ceil(std::max({y0, y1, y2}))));
    if (xmin > xmax || ymin > ymax) continue;
    double len[3] = {std::hypot(x2 - x1, y2 - y1), std::hypot(x0 - x2, y0 - y2),
                     std::hypot(x1 - x0, y1 - y0)};
    double iz[3] = {1 / sz[t[0]], 1 / sz[t[1]], 1 / sz[t[2]]};
    double inv_area = 1 / area;
    for (int y = ymin; y <= ymax; ++y) {
      double py = y + 0.5;
      for (int x = xmin; x <= xmax; ++x) {
        double px = x + 0.5;
        // Edge functions, signed like `area`, so all three are >= 0 inside for either winding.
        double e0 = ((x2 - x1) * (py - y1) - (y2 - y1) * (px - x1)) * inv_area;
        double e1 = ((x0 - x2) * (py - y2) - (y0 - y2) * (px - x2)) * inv_area;
        double e2 = 1 - e0 - e1;
        if (e0 < 0 || e1 < 0 || e2 < 0) continue;
        std::size_t pix = static_cast<std::size_t>(y) * W + x;
        double d = e0 * iz[0] + e1 * iz[1] + e2 * iz[2];
        if (d <= inv_z[pix]) continue;
        inv_z[pix] = d;
        Vec3 n = o.smooth ? normalized(vert_n[t[0]] * e0 + vert_n[t[1]] * e1 + vert_n[t[2]] * e2) : face_n[f];
        // Two-sided: a face seen from behind is lit like its front (open meshes, flipped faces).
        double shade = 0.28 + 0.72 * std::abs(dot(n, light));
        bool edge = false;
        if (o.wireframe) {
          // Pixel distance to the edge opposite vertex i is e_i * |2 area| / |edge i|.
          double a2 = std::abs(area);
          edge = e0 * a2 / len[0] < wire_px || e1 * a2 / len[1] < wire_px || e2 * a2 / len[2] < wire_px;
        }
        for (int k = 0; k < 3; ++k) {
          double c = (e0 * color[3 * t[0] + k] + e1 * color[3 * t[1] + k] + e2 * color[3 * t[2] + k]) * shade;
          rgb[3 * pix + k] = static_cast<float>(edge ? 0.3 * c + 0.7 * kWire[k] : c);
        }
      }
    }
  }

  // Legend for the heat map: a vertical colour bar at the right edge, low values at the bottom.
  if (heat && hhi > hlo) {
    int bw = std::max(2, W / 60), x1 = W - bw * 2, y0 = H / 5, y1 = H - H / 5;
    for (int y = y0; y < y1; ++y) {
      auto c = heat_color(1 - static_cast<double>(y - y0) / std::max(1, y1 - y0 - 1));
      for (int x = x1; x < x1 + bw && x < W; ++x)
        for (int k = 0; k < 3; ++k)
          rgb[3 * (static_cast<std::size_t>(y) * W + x) + k] = static_cast<float>(c[k]);
    }
  }

  // Box-filter the supersamples down to the output pixels.
  Image img;
  img.width = o.width;
  img.height = o.height;
  img.rgb.resize(static_cast<std::size_t>(o.width) * o.height * 3);
  const double norm = 255.0 / (ss * ss);
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x)
      for (int k = 0; k < 3; ++k) {
        double sum = 0;
        for (int j = 0; j < ss; ++j)
          for (int i = 0; i < ss; ++i)
            sum += rgb[3 * ((static_cast<std::size_t>(y) * ss + j) * W + x * ss + i) + k];
        img.rgb[3 * (static_cast<std::size_t>(y) * o.width + x) + k] =
            static_cast<std::uint8_t>(std::clamp(std::lround(sum * norm), 0L, 255L));
      }
  return img;
}

}  // namespace qem::view
