// Uniform area sampling of a triangle surface (GH97 §6.1 measures E_i over points "sampled" on both
// surfaces; we sample uniformly by area so that the sum approximates the surface integral).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "qem/mesh.h"

namespace qem::measure_detail {

/// The non-degenerate triangles of a mesh as flat corner coordinates, ready for sampling and the BVH.
struct Surface {
  std::vector<double> corners;         ///< 9 per kept triangle: a.xyz b.xyz c.xyz
  std::vector<double> cum_area;        ///< prefix sums of the kept triangles' areas (the sampling CDF)
  std::vector<std::uint32_t> face_of;  ///< the input face of each kept triangle (for its attributes)
  std::vector<double> vertices;        ///< xyz of every vertex referenced by a face (Hausdorff candidates)
  double area = 0;
  std::size_t faces = 0;       ///< input faces
  std::size_t degenerate = 0;  ///< zero-area faces: ignored for sampling and distance
  std::size_t triangle_count() const { return cum_area.size(); }
};

/// Collects the triangles of `mesh`; throws qem::Error naming `what` on out-of-range indices.
Surface make_surface(MeshView mesh, const char* what);

/// Where a sample lies: a kept triangle and the barycentric weights of its corners a, b, c.
struct SamplePlace {
  std::uint32_t triangle = 0;
  double w[3] = {0, 0, 0};
};

/// `n` points uniformly distributed by area (face by area CDF, then uniform barycentric
/// coordinates via the square-root warp), from xoshiro256** seeded with `seed`. Flat xyz.
/// `places`, if given, receives each point's triangle and weights (to interpolate attributes there).
std::vector<double> sample_surface(const Surface& surface, std::size_t n, std::uint64_t seed,
                                   std::vector<SamplePlace>* places = nullptr);

}  // namespace qem::measure_detail
