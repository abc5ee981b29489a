// The largest distance from surface FROM to surface TO, sampled densely: a K-division grid on
// every face of FROM, then the TOP farthest faces again on a KREFINE-division grid. The harness
// metric's random samples (a few per face) miss peaks that sit between them, on an edge or at a
// lone face; docs/benchmarks.md ("Far places") compares qem and its peers with this.
//
// Build against a Release build of qem (internal headers; not part of the library):
//   g++ -std=c++20 -O2 -Iinclude -Isrc scripts/dense_distance.cpp build/libqem.a -lpthread -o /tmp/dense_distance
// Usage: dense_distance FROM TO K TOP KREFINE   (e.g. output input 12 300 100; input output 4 1000 60)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <vector>

#include "geometry/box.h"
#include "geometry/frame.h"
#include "qem/io.h"
#include "refit/refit_points.h"

using namespace qem;

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr, "usage: %s FROM TO K TOP KREFINE\n", argv[0]);
    return 2;
  }
  const Mesh from = load_mesh(argv[1]), to = load_mesh(argv[2]);
  const int k = std::atoi(argv[3]), top = std::atoi(argv[4]), k_refine = std::atoi(argv[5]);
  if (k < 1 || top < 1 || k_refine < 1 || from.face_count() == 0) {
    std::fprintf(stderr, "K, TOP and KREFINE must be positive, FROM must have faces\n");
    return 2;
  }
  const Frame frame = frame_of_box(box_of_points(to.positions));
  const auto surface = refit_detail::surface_in_frame(to.positions, to.indices, frame);
  const auto corner = [&](std::size_t f, int c) {
    const double* p = &from.positions[3 * std::size_t(from.indices[3 * f + c])];
    return frame.to_frame({p[0], p[1], p[2]});
  };
  // The largest distance over face f's grid of n divisions, and where it is.
  const auto face_largest = [&](std::size_t f, int n, Vec3& where) {
    const Vec3 a = corner(f, 0), b = corner(f, 1), c = corner(f, 2);
    std::uint32_t hint = UINT32_MAX;
    double most = -1;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const Vec3 q = a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n);
        const double d = surface.distance(q, &hint);
        if (d > most) most = d, where = q;
      }
    return most;
  };
  std::vector<std::pair<double, std::size_t>> faces(from.face_count());
  Vec3 where{};
  for (std::size_t f = 0; f < faces.size(); ++f) faces[f] = {face_largest(f, k, where), f};
  const std::size_t refined = std::min<std::size_t>(std::size_t(top), faces.size());
  std::partial_sort(faces.begin(), faces.begin() + std::ptrdiff_t(refined), faces.end(), std::greater<>());
  double best = -1;
  std::size_t best_face = 0;
  Vec3 best_at{};
  for (std::size_t i = 0; i < refined; ++i) {
    const double d = face_largest(faces[i].second, k_refine, where);
    if (d > best) best = d, best_face = faces[i].second, best_at = where;
  }
  const Vec3 at = frame.to_model(best_at);
  std::printf("grid %.6g refined %.6g (model units; of TO's diagonal %.6g) face %zu at %.9g %.9g %.9g\n",
              faces[0].first * frame.scale, best * frame.scale, best, best_face, at.x, at.y, at.z);
  return 0;
}
