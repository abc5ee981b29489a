// The refit of qem/refit.h against weighted points rather than a mesh, so that `simplify` can
// refit its output after it has released the input's faces (it keeps the per-vertex weights).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/default_init_allocator.h"
#include "core/distance_bound.h"
#include "geometry/frame.h"
#include "geometry/vec3.h"
#include "qem/mesh.h"
#include "qem/refit.h"

namespace qem::refit_detail {

/// A third of the area of each face around each vertex: the vertex's share of the surface, so
/// that sums over vertices approximate integrals over the surface (HG99 §2's area weighting).
/// The mesh must have passed check_mesh (simplify and qem::refit check it first). On up to
/// `threads` threads, the same result on any number.
std::vector<double> vertex_areas(MeshView mesh, unsigned threads = 1);

/// The points an approximation is fitted to, in the refit's normalised frame: made once for any
/// number of approximations of the same original.
struct FitPoints {
  FitPoints() = default;
  /// Points of 3 doubles each, with the given weights; the points of weight 0 are left out. Made
  /// on up to `threads` threads, the same on any number.
  FitPoints(std::span<const double> points, std::span<const double> weights, unsigned threads = 1);
  /// One point for each run of `group` consecutive points in Morton order: the run's middle
  /// point, carrying the run's summed weight (RefitOptions::points_per_vertex). Same frame; the
  /// same points on any number of `threads`.
  FitPoints thinned(std::size_t group, unsigned threads = 1) const;
  // (Filled on the threads when made, not zeroed first: on a large input these are otherwise a
  // serial stretch of fresh pages.)
  core::UnzeroedVector<double> position;       ///< 3 per kept point, normalised
  core::UnzeroedVector<double> weight;         ///< one per kept point
  std::vector<std::uint32_t> order;            ///< Morton order of the kept points (warm-started queries)
  core::UnzeroedVector<std::uint32_t> source;  ///< index of each kept point among the points given
  /// The frame of the kept points' box (geometry/frame.h), in which `position` is given: its
  /// centre and scale (the box's diagonal).
  Vec3 centre;
  double diag = 1;
  Frame frame() const { return {centre, diag}; }
  double total_weight = 0;
};

/// Throws qem::Error if an option is out of range (qem::refit, and simplify for its refit).
void check_options(const RefitOptions& options);

/// Refits `approx` (a mesh that has passed check_mesh; the options checked by the caller) to the
/// points. `near_vertex` (optional), per point given to FitPoints: a vertex of `approx` near it
/// (UINT32_MAX: none), such as the output vertex `simplify` contracted it into; the first search
/// for its closest face walks from there instead of asking a tree of all faces.
/// `surface` (optional): the original's surface in the points' frame (surface_in_frame), for the
/// guard that keeps the approximation as close to the original as it was (and within
/// options.max_distance).
/// `closest_faces` (optional): set to each point's closest face of the refitted approximation
/// (UINT32_MAX: none found), walked to from the refit's last projection, for the far-place repair
/// that follows: the tree's answer but where a closer face lies beyond a farther one. The repair
/// measures every point again, so with it the refit keeps its last round without projecting the
/// points once more when their distances to their faces of the projection before add up to less
/// than the error before the round (an upper bound of the error after it, which rms_after then
/// is): those faces, mostly the same, are then the ones handed on.
RefitResult refit_to_points(const FitPoints& points, Mesh& approx, const RefitOptions& options,
                            std::span<const std::uint32_t> near_vertex = {},
                            const core::SurfaceDistance* surface = nullptr,
                            std::vector<std::uint32_t>* closest_faces = nullptr);

/// The surface of an original (positions, triangle indices) in `frame` (FitPoints::frame()), made
/// on up to `threads` threads (the same surface on any number).
core::SurfaceDistance surface_in_frame(std::span<const double> positions, std::span<const std::uint32_t> indices,
                                       const Frame& frame, unsigned threads = 1);

}  // namespace qem::refit_detail
