// SimplifyOptions::max_distance: no output point farther than D from the input surface, checked
// on each contraction's new faces against a bounding volume hierarchy of the input (as CGAL's
// bounded-distance placement does for the new vertex, but here for every point of the faces).
//
// The check is exact in what it accepts (a certificate, never a guess) and adaptive in its work:
// for a triangle (or a piece of it), let m be its centroid, T the input triangle closest to m,
// and R the farthest corner's distance from m.
//   - the distance to a fixed surface is 1-Lipschitz, so if d(m) + R <= D the piece lies within D;
//   - the distance to the one triangle T is convex, so its largest value over the piece is at a
//     corner; the surface is at least as close as T, so if every corner is within D of T, the
//     whole piece is within D of the surface;
//   - if d(m) > D, the piece is not within D;
//   - else the piece splits into four at its edges' midpoints, down to kMaxDepth levels (4^6
//     pieces at most); a piece still undecided there counts as too far (the contraction is
//     refused: conservative).
#pragma once

#include <cmath>
#include <cstdint>
#include <utility>
#include <span>
#include <vector>

#include "core/default_init_allocator.h"
#include "core/working_mesh.h"
#include "geometry/vec3.h"
#include "measure/bvh.h"

namespace qem::core {

inline constexpr int kMaxDepth = 6;

class SurfaceDistance {
 public:
  SurfaceDistance() = default;
  /// `corners`: 9 doubles per triangle of the surface (a.xyz b.xyz c.xyz); its tree is built on up
  /// to `threads` threads (the same tree on any number).
  explicit SurfaceDistance(std::span<const double> corners, unsigned threads = 1) : tree_(corners, threads) {}
  /// Per vertex of the surface's mesh, one triangle that has it (UINT32_MAX: none): a start for
  /// searches from points known to lie near a vertex (face_at).
  using FaceAtVertex = UnzeroedVector<std::uint32_t>;
  /// Of an indexed mesh (TriangleBvh's second form: it keeps `vertices`), with a face at each vertex.
  SurfaceDistance(UnzeroedVector<double> vertices, std::span<const std::uint32_t> indices,
                  FaceAtVertex face_at_vertex, unsigned threads = 1)
      : tree_(std::move(vertices), indices, threads), face_at_vertex_(std::move(face_at_vertex)) {}
  bool empty() const { return tree_.empty(); }
  /// A triangle that has vertex v, or UINT32_MAX (unknown).
  std::uint32_t face_at(std::uint32_t v) const {
    return v < face_at_vertex_.size() ? face_at_vertex_[v] : UINT32_MAX;
  }

  /// Distance from p to the surface; `hint` as TriangleBvh::closest (warm start).
  double distance(const Vec3& p, std::uint32_t* hint) const {
    const double q[3] = {p.x, p.y, p.z};
    return std::sqrt(tree_.closest(q, hint).d2);
  }
  /// Whether p is within d of the surface: distance(p, &hint) <= d, decided for the price of one
  /// triangle when triangle `hint` (not UINT32_MAX) is itself within d (the minimum over all
  /// triangles is then too); else `hint` is set as by distance().
  bool within(const Vec3& p, double d, std::uint32_t& hint) const {
    const double q[3] = {p.x, p.y, p.z};
    if (hint != UINT32_MAX && std::sqrt(tree_.triangle_d2(q, hint)) <= d) return true;
    return distance(p, &hint) <= d;
  }
  /// The point of the surface closest to p; `hint` as in distance().
  Vec3 closest_point(const Vec3& p, std::uint32_t* hint) const {
    const double q[3] = {p.x, p.y, p.z};
    const measure_detail::TriangleBvh::Hit hit = tree_.closest(q, hint);
    return {hit.point[0], hit.point[1], hit.point[2]};
  }
  /// The triangles of the surface within `radius` of p (appended to `out`, in no fixed order).
  void triangles_near(const Vec3& p, double radius, std::vector<std::uint32_t>& out) const {
    const double q[3] = {p.x, p.y, p.z};
    tree_.within(q, radius * radius, out);
  }
  /// The corners of triangle t (9 doubles).
  std::array<double, 9> triangle(std::uint32_t t) const { return tree_.triangle(t); }
  /// Distance from p to triangle t of the surface (at least distance(p)).
  double distance_to(const Vec3& p, std::uint32_t t) const {
    const double q[3] = {p.x, p.y, p.z};
    return std::sqrt(tree_.triangle_d2(q, t));
  }
  /// Whether every point of triangle abc is certified within d of the surface (see above).
  bool triangle_within(const Vec3& a, const Vec3& b, const Vec3& c, double d) const {
    return piece_within(a, b, c, d, 0, UINT32_MAX);
  }
  /// The largest distance to the surface over the corners, edge midpoints and centroid of abc
  /// and of its four halves-by-edge (a lower bound of the triangle's largest distance).
  double triangle_sampled_max(const Vec3& a, const Vec3& b, const Vec3& c) const;

 private:
  /// `parent`: the closest triangle to the centroid of the piece this one was split from
  /// (UINT32_MAX at the top).
  bool piece_within(const Vec3& a, const Vec3& b, const Vec3& c, double d, int depth, std::uint32_t parent) const;

  measure_detail::TriangleBvh tree_;
  FaceAtVertex face_at_vertex_;
};

/// The corners of the live faces of `mesh` (9 doubles per face), for a SurfaceDistance.
std::vector<double> live_face_corners(const WorkingMesh& mesh);

/// Whether contracting (a, b) to `target` keeps every new face (the faces of a and b that do not
/// have both) certified within d of the surface.
bool contraction_within(const SurfaceDistance& surface, double d, const WorkingMesh& mesh, std::uint32_t a,
                        std::uint32_t b, const Vec3& target);

}  // namespace qem::core
