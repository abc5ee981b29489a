// Refitting an approximation to the original surface with its connectivity fixed: the vertex
// optimisation step of Hoppe, DeRose, Duchamp, McDonald and Stuetzle 1993, "Mesh optimization"
// (§4.2, "optimization over V for fixed K"), run once after simplification.
//
// GH97 places each new vertex where it minimises the sum of squared distances to the planes of
// the faces it stands for (§4). Those planes are the input's tangent planes, which a coarse face
// strays from, and later contractions move the vertex's neighbours again. Refitting minimises the
// true squared distance from the original's vertices (each weighted by its share of the surface
// area, so the sum approximates the surface integral of GH97 §6.1's E) to the approximation:
// project every original vertex onto its closest approximation face, solve the linear least
// squares problem for the vertex positions with those projections fixed, repeat.
#pragma once

#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include "qem/mesh.h"

namespace qem {

struct RefitOptions {
  /// Project-then-solve rounds. Each lowers the fit's error or is undone, and the refit stops.
  unsigned rounds = 3;
  bool lock_border = false;  ///< vertices on the approximation's border stay where they are
  /// A face whose normal turns by more than this (degrees) in one round undoes the moves of its
  /// vertices for that round (the refit never folds the surface over; GH97 §6's inversion test).
  double max_normal_turn_degrees = 75;
  /// Threads for the closest-point queries (0 = all hardware threads); the result does not
  /// depend on it.
  unsigned threads = 0;
  /// Fit to about this many of the original's vertices per approximation vertex; 0 = all of them.
  /// Every k-th vertex along a Morton curve stands for its k neighbours (their summed area), so
  /// the cost follows the approximation's size, not the original's. 2 is about the fewest that
  /// fit a noisy surface rather than its noise; with fewer points the reported RMS is over them.
  double points_per_vertex = 0;
  /// Per approximation vertex (empty: none), nonzero = it stays where it is (simplify passes its
  /// SimplifyOptions::vertex_lock through). The caller's buffer must outlive the call.
  std::span<const std::uint8_t> fixed_vertices;
  /// No point of the approximation moves farther than this from the original's surface (distance
  /// units; +inf = no bound beyond the guard below). Whatever it is, a move that takes a vertex or
  /// a face centroid farther from the original than the approximation's largest such distance
  /// before the refit (plus 2 % of it) is undone.
  double max_distance = std::numeric_limits<double>::infinity();
};

struct RefitResult {
  /// Area-weighted RMS distance from the original's vertices to the approximation, before and
  /// after, in model units. `rms_after <= rms_before` always.
  double rms_before = 0, rms_after = 0;
  std::size_t rounds = 0;         ///< rounds kept (each lowered rms)
  std::size_t vertices_held = 0;  ///< moves undone over the kept rounds to keep faces from turning
};

/// Moves the vertices of `approx` to fit `original` better; faces and vertex order are unchanged,
/// and a vertex that does not move keeps its exact coordinates. Deterministic for any thread
/// count; invariant to the model's scale and position (up to rounding). Throws qem::Error on an
/// out-of-range index, a non-finite coordinate or an option out of range.
RefitResult refit(MeshView original, Mesh& approx, const RefitOptions& options = {});

/// Refits several approximations of one original (the levels of a chain), each exactly as the
/// single refit above would, with the work on the original (its validation, area weights and
/// spatial order) done once. Results in the order of `approximations`.
std::vector<RefitResult> refit(MeshView original, std::span<Mesh* const> approximations,
                               const RefitOptions& options = {});

}  // namespace qem
