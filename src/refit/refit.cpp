// Refit of an approximation's vertices with its faces fixed (Hoppe et al. 1993, §4.2).
//
// One round, in a frame normalised to the bounding-box diagonal (so nothing depends on scale or
// position):
//   project   (with the original's surface: a point farther from its closest face than
//             kFarHausdorff times the approximation's largest distance to the original stands for
//             surface the simplification removed, not for this face: it does not pull)
//             each original vertex p_i (weight w_i, its area share; with points_per_vertex, every
//             k-th along the Morton order, carrying the area of its run of k) onto its closest
//             approximation face t_i, at barycentric coordinates b_i: first a bounding volume
//             hierarchy query, or, after `simplify`, a walk from the output vertex the point was
//             contracted into; then (the moves of a round being small) the closest of the faces
//             around the corners of the point's face of the round before; on all threads over
//             fixed chunks in Morton order (the answer does not depend on the threads);
//   solve     min over X of  sum_i w_i |b_i . X(t_i) - p_i|^2            (the fit)
//                            + kappa sum_edges |D_r - D_c|^2, D = X - X_old  (a membrane)
//                            + lambda sum_v |D_v|^2                          (a small anchor),
//             a sparse symmetric positive definite system (one per coordinate, same matrix): the
//             fit is a finite-element mass matrix, well conditioned, so conjugate gradients with a
//             diagonal preconditioner converge in a dozen steps, the three coordinates together.
//             Hoppe's spring term pulls on the positions, which shrinks curved surfaces; the
//             membrane here pulls on the displacement, so it only keeps neighbours moving together
//             (no vertex jumps off alone to fit a few points), and the anchor holds vertices no
//             point reaches;
//   guard     a face whose normal turned by more than the limit undoes its vertices' moves, until
//             none does (GH97 §6: the refit never folds the surface); with the original's
//             surface, a moved vertex or face centroid farther from it than the approximation's
//             largest such distance before the refit (plus kHausdorffMargin of it) undoes its
//             moves too, as does a face no longer certified within max_distance: the refit never
//             raises the one-sided Hausdorff distance (approximation to original, over those
//             samples) by more than the margin, and never breaks the distance bound;
//   keep      the round only if the fit's error went down; else undo it and stop.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>

#include "check_mesh.h"
#include "core/default_init_allocator.h"
#include "core/distance_bound.h"
#include "core/parallel_chunks.h"
#include "core/spatial_order.h"
#include "core/valid_pairs.h"
#include "core/vertex_lists.h"
#include "geometry/box.h"
#include "geometry/frame.h"
#include "geometry/vec3.h"
#include "measure/bvh.h"
#include "measure/point_triangle.h"
#include "qem/error.h"
#include "refit/refit_points.h"

namespace qem {

namespace refit_detail {

namespace {

constexpr std::size_t kChunk = 4096;  // queries per work item and per warm-start run
/// lambda of the anchor, relative to the mean data weight of a vertex: small enough not to hold
/// the fit back (a ten times larger one left E practically unchanged), large enough to make the
/// system definite (docs/benchmarks.md, "Measurements behind the code").
constexpr double kAnchor = 1e-3;
/// kappa of the membrane on the displacement, relative to the mean data weight (both scale with
/// the area per vertex, so the ratio holds at any resolution). Without it a vertex that only a few
/// points reach, at small barycentric weights, can jump off the surface to fit them: E falls but
/// the Hausdorff distance rises. On the 12 benchmark cases 0.03 still let it rise and 1 gave back
/// E; 0.3 keeps it close to the unrefitted output's (docs/benchmarks.md: "Measurements behind the
/// code", "Tried and dropped").
constexpr double kMembrane = 0.3;
/// A point farther from the approximation than this many times the approximation's largest
/// distance to the original (over its vertices and face centroids, before the refit) pulls
/// nothing: its surface was contracted away (a spike, a thin part, a vanished component), and
/// fitting the survivor to it moves the survivor off the original (issue 21: up to 7 % of the
/// diagonal). Where the surface survived, the original lies about as far from the approximation
/// as the approximation from the original. (A bound relative to the faces' edge lengths, tried
/// first, also cut off the points a crude approximation should be pulled to.)
constexpr double kFarHausdorff = 2;
/// The refit may raise the sampled one-sided Hausdorff distance (approximation to original, over
/// vertices and face centroids) by at most this fraction of its value before the refit.
constexpr double kHausdorffMargin = 0.02;
/// Doubles per face in Refitter::bounding_spheres: centre, radius, unit normal, padding.
constexpr std::size_t kSphere = 8;
/// Those spheres: every double written (on the threads) before any is read.
using Spheres = core::UnzeroedVector<double>;

Vec3 at(const std::vector<double>& x, std::uint32_t v) { return {x[3 * v], x[3 * v + 1], x[3 * v + 2]}; }

Vec3 face_normal(const std::vector<double>& x, const std::uint32_t* t) {
  return cross(at(x, t[1]) - at(x, t[0]), at(x, t[2]) - at(x, t[0]));
}

/// Barycentric coordinates of q (a point of triangle abc) in abc; false if abc has no area.
bool barycentric(Vec3 q, Vec3 a, Vec3 b, Vec3 c, double out[3]) {
  const Vec3 e0 = b - a, e1 = c - a, d = q - a;
  const double d00 = dot(e0, e0), d01 = dot(e0, e1), d11 = dot(e1, e1), d20 = dot(d, e0), d21 = dot(d, e1);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 1e-30 * d00 * d11) || !(den > 0)) return false;
  out[1] = (d11 * d20 - d01 * d21) / den;
  out[2] = (d00 * d21 - d01 * d20) / den;
  out[0] = 1 - out[1] - out[2];
  return true;
}

/// Where each point lands on the approximation.
/// (Not zero-filled when made: each point's entries are written by the thread that projects it,
/// so the fresh pages of a multi-million-point projection are touched on all threads.)
struct Projection {
  template <class T>
  using Array = core::UnzeroedVector<T>;
  Array<std::uint32_t> nearest;  ///< closest face, UINT32_MAX = none (where the next round looks)
  Array<std::uint32_t> face;     ///< the same face if it pulls the point (has area), else UINT32_MAX
  Array<double> bary;            ///< 3 per point, read only where face is set
  /// 1 where `nearest` is where a walk from it would stay: the tree's answer, or a local search's
  /// that is its own start (closest_faces then needs no walk).
  Array<std::uint8_t> settled;
  double energy = 0;  ///< sum of w_i * squared distance
};

}  // namespace

// Everything about the points that does not depend on the approximation: made once for all the
// approximations of one original (`qem lod --refit`).
FitPoints::FitPoints(std::span<const double> points, std::span<const double> weights, unsigned threads) {
  // The points with a weight, their box and their place in the frame, in fixed chunks on the
  // threads (a chunk's kept points go after the earlier chunks'; its box is merged in chunk order,
  // min and max being exact): the same points in the same order on any number of threads. On a
  // ten-million-face input this was a serial stretch beside the parallel refit.
  const std::size_t n = weights.size(), chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::size_t> first(chunks + 1, 0);
  std::vector<BoxOfPoints> boxes(chunks);
  core::for_chunks(n, kChunk, threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    std::size_t kept = 0;
    for (std::size_t i = begin; i < end; ++i)
      if (weights[i] > 0) ++kept, boxes[c].add(&points[3 * i]);
    first[c + 1] = kept;
  });
  BoxOfPoints all;
  for (std::size_t c = 0; c < chunks; ++c) first[c + 1] += first[c], all.add(boxes[c]);
  const std::size_t m = first[chunks];
  // The frame of the points' box (the approximation's vertices lie near them). Points that all
  // coincide leave nothing to fit.
  const Box box = all.box();
  const Frame f = frame_of_box(box);
  centre = f.center, diag = f.scale;
  if (m == 0 || !(box.diagonal() > 0)) return;
  position.resize(3 * m);
  weight.resize(m);
  source.resize(m);
  core::for_chunks(n, kChunk, threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    std::size_t j = first[c];
    for (std::size_t i = begin; i < end; ++i) {
      if (!(weights[i] > 0)) continue;
      const double* p = &points[3 * i];
      const Vec3 q = f.to_frame({p[0], p[1], p[2]});
      position[3 * j] = q.x, position[3 * j + 1] = q.y, position[3 * j + 2] = q.z;
      weight[j] = weights[i];
      source[j] = std::uint32_t(i);
      ++j;
    }
  });
  for (std::size_t j = 0; j < m; ++j) total_weight += weight[j];  // in point order, as always
  order = core::morton_order(m, [&](std::size_t j) {
    return Vec3(position[3 * j], position[3 * j + 1], position[3 * j + 2]);
  }, threads);
}

FitPoints FitPoints::thinned(std::size_t group, unsigned threads) const {
  FitPoints out;
  out.centre = centre, out.diag = diag;
  const std::size_t n = order.size(), runs = (n + group - 1) / group;
  out.position.resize(3 * runs), out.weight.resize(runs), out.source.resize(runs), out.order.resize(runs);
  // Each run on its own (in fixed chunks of runs on the threads); the total in run order.
  core::for_chunks(runs, kChunk, threads, [&](std::size_t, std::size_t first_run, std::size_t end_run) {
    for (std::size_t r = first_run; r < end_run; ++r) {
      const std::size_t begin = r * group, end = std::min(n, begin + group);
      double w = 0;
      for (std::size_t k = begin; k < end; ++k) w += weight[order[k]];
      const std::uint32_t middle = order[begin + (end - begin) / 2];
      std::copy_n(&position[3 * std::size_t(middle)], 3, &out.position[3 * r]);
      out.weight[r] = w;
      out.source[r] = source[middle];
      out.order[r] = std::uint32_t(r);  // runs follow the Morton order
    }
  });
  for (std::size_t r = 0; r < runs; ++r) out.total_weight += out.weight[r];
  return out;
}

namespace {

/// The refit's normal equations: a symmetric sparse matrix by rows (compressed), each row's
/// columns in increasing order.
struct SparseRows {
  std::vector<std::uint32_t> start{0}, column;
  std::vector<double> value, diagonal;
};

/// y = a x for the three coordinates at once (x, y: 3 per vertex): each row of a read once, rows
/// in fixed chunks on the threads (each row's sum is made as on one thread).
void multiply(const SparseRows& a, std::span<const double> x, std::span<double> y, unsigned threads) {
  core::for_chunks(a.diagonal.size(), std::size_t(1) << 14, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) {
      double sum[3] = {0, 0, 0};
      for (std::uint32_t e = a.start[v]; e < a.start[v + 1]; ++e) {
        const double* xc = &x[3 * std::size_t(a.column[e])];
        for (int k = 0; k < 3; ++k) sum[k] += a.value[e] * xc[k];
      }
      for (int k = 0; k < 3; ++k) y[3 * v + k] = sum[k];
    }
  });
}

/// Solves a x = b for the three coordinates at once, from the x given: conjugate gradients with a
/// diagonal preconditioner, each coordinate to a residual of kTolerance |b| (then it stops
/// moving). Eigen's solver takes one right-hand side at a time and so reads the matrix three times
/// a step; this reads it once (docs/benchmarks.md, "Measurements behind the code").
void conjugate_gradients(const SparseRows& a, const std::vector<double>& b, std::vector<double>& x, unsigned threads) {
  constexpr double kTolerance = 1e-10;
  constexpr int kMaxSteps = 1000;
  const std::size_t n = a.diagonal.size();
  // Written whole below before they are read; first touched on the threads.
  core::UnzeroedVector<double> r = core::filled(3 * n, 0.0, threads), z = core::filled(3 * n, 0.0, threads),
                               p = core::filled(3 * n, 0.0, threads), q = core::filled(3 * n, 0.0, threads);
  double limit[3] = {0, 0, 0}, rz[3] = {0, 0, 0}, rr[3] = {0, 0, 0};
  multiply(a, x, q, threads);
  for (std::size_t v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k) {
      const std::size_t i = 3 * v + k;
      limit[k] += b[i] * b[i];
      r[i] = b[i] - q[i];
      z[i] = p[i] = r[i] / a.diagonal[v];
      rz[k] += r[i] * z[i], rr[k] += r[i] * r[i];
    }
  for (double& l : limit) l *= kTolerance * kTolerance;
  for (int step = 0; step < kMaxSteps; ++step) {
    bool moving[3], any = false;
    for (int k = 0; k < 3; ++k) any |= moving[k] = rr[k] > limit[k];
    if (!any) break;
    multiply(a, p, q, threads);
    double pq[3] = {0, 0, 0};
    for (std::size_t i = 0; i < 3 * n; ++i) pq[i % 3] += p[i] * q[i];
    double alpha[3];
    for (int k = 0; k < 3; ++k) alpha[k] = moving[k] && pq[k] > 0 ? rz[k] / pq[k] : 0.0;
    double rz_next[3] = {0, 0, 0};
    rr[0] = rr[1] = rr[2] = 0;
    for (std::size_t v = 0; v < n; ++v)
      for (int k = 0; k < 3; ++k) {
        const std::size_t i = 3 * v + k;
        x[i] += alpha[k] * p[i];
        r[i] -= alpha[k] * q[i];
        z[i] = r[i] / a.diagonal[v];
        rz_next[k] += r[i] * z[i], rr[k] += r[i] * r[i];
      }
    for (int k = 0; k < 3; ++k) {
      const double beta = rz[k] > 0 ? rz_next[k] / rz[k] : 0.0;
      rz[k] = rz_next[k];
      for (std::size_t v = 0; v < n; ++v) p[3 * v + k] = z[3 * v + k] + beta * p[3 * v + k];
    }
  }
}

class Refitter {
 public:
  Refitter(const FitPoints& points, Mesh& approx, const RefitOptions& o,
           std::span<const std::uint32_t> near_vertex, const core::SurfaceDistance* surface)
      : approx_(approx),
        opt_(o),
        tri_(approx.indices),
        pts_(points),
        near_vertex_(near_vertex),
        frame_(points.frame()),
        surface_(surface && !surface->empty() ? surface : nullptr),
        max_distance_(o.max_distance / points.frame().scale) {
    if (pts_.weight.empty() || approx.indices.empty()) return;
    x_.resize(approx.positions.size());
    for (std::size_t v = 0; v < approx.vertex_count(); ++v) {
      const Vec3 q = frame_.to_frame(at(approx.positions, std::uint32_t(v)));
      x_[3 * v] = q.x, x_[3 * v + 1] = q.y, x_[3 * v + 2] = q.z;
    }
    fixed_.assign(approx.vertex_count(), 0);
    if (o.lock_border) mark_border();
    if (!o.fixed_vertices.empty()) {
      if (o.fixed_vertices.size() != fixed_.size())
        throw Error("refit: fixed_vertices has " + std::to_string(o.fixed_vertices.size()) + " entries for " +
                    std::to_string(fixed_.size()) + " vertices");
      for (std::size_t v = 0; v < fixed_.size(); ++v) fixed_[v] |= o.fixed_vertices[v] != 0;
    }
    // Faces around each vertex (CSR), for the projections after the first.
    ring_start_.assign(approx.vertex_count() + 1, 0);
    for (std::uint32_t v : tri_) ++ring_start_[v + 1];
    for (std::size_t v = 0; v < approx.vertex_count(); ++v) ring_start_[v + 1] += ring_start_[v];
    ring_faces_.resize(tri_.size());
    ring_slot_.resize(tri_.size());
    std::vector<std::uint32_t> fill(ring_start_.begin(), ring_start_.end() - 1);
    for (std::size_t c = 0; c < tri_.size(); ++c) {
      ring_slot_[c] = fill[tri_[c]]++;
      ring_faces_[ring_slot_[c]] = std::uint32_t(c / 3);
    }
    make_around();
    // A start for each vertex's search of the original: of the faces at the input vertices
    // contracted into it (one each), the nearest.
    if (surface_ && !near_vertex_.empty()) {
      // The distances on the threads (one per input vertex, in fixed chunks), the choice in input
      // order as before: the same faces on any number of threads.
      original_face_near_.assign(approx.vertex_count(), UINT32_MAX);
      core::UnzeroedVector<double> distance(near_vertex_.size());
      core::for_chunks(near_vertex_.size(), kChunk, core::resolve_threads(o.threads),
                       [&](std::size_t, std::size_t begin, std::size_t end) {
                         for (std::size_t i = begin; i < end; ++i) {
                           const std::uint32_t v = near_vertex_[i], f = surface_->face_at(std::uint32_t(i));
                           distance[i] = v >= original_face_near_.size() || f == UINT32_MAX
                                             ? HUGE_VAL
                                             : surface_->distance_to(at(x_, v), f);
                         }
                       });
      std::vector<double> nearest(approx.vertex_count(), HUGE_VAL);
      for (std::size_t i = 0; i < near_vertex_.size(); ++i) {
        const std::uint32_t v = near_vertex_[i];  // no face or no vertex: HUGE_VAL, never nearer
        if (v < original_face_near_.size() && distance[i] < nearest[v])
          nearest[v] = distance[i], original_face_near_[v] = surface_->face_at(std::uint32_t(i));
      }
    }
    ready_ = true;
  }

  // `last_on_bound`: the last round is kept when its error on each point's face of the projection
  // before it (an upper bound: the point's closest face is at most as far) is below the error
  // before it, without a projection of its own, and rms_after is that bound. For a caller that
  // measures every point again (the far-place repair): the projection would only confirm the
  // round, and the faces it finds are mostly those of the round before (docs/benchmarks.md).
  RefitResult run(bool last_on_bound) {
    RefitResult r;
    if (!ready_) return r;
    const std::vector<double> start = x_;
    if (surface_) {
      const double h0 = largest_distance(x_);
      limit_ = h0 * (1 + kHausdorffMargin) + 1e-12;  // 1e-12: rounding, of the diagonal
      far_ = kFarHausdorff * h0 + 1e-12;
    }
    Projection proj = project(x_);
    r.rms_before = r.rms_after = std::sqrt(proj.energy / pts_.total_weight) * frame_.scale;
    for (unsigned round = 0; round < opt_.rounds; ++round) {
      std::vector<double> next;
      if (!solve(proj, next)) break;
      // What is read of this projection from here on is each point's closest face (where the
      // next one starts), whether it is settled, and its energy: the rest goes before the next is
      // made (on a large input the points' arrays are the refit's largest).
      Projection::Array<std::uint32_t>().swap(proj.face);
      Projection::Array<double>().swap(proj.bary);
      std::size_t held = hold_turned_faces(next);
      if (surface_) held += hold_far_from_original(next);
      Projection next_proj;
      const double bound =
          last_on_bound && round + 1 == opt_.rounds ? energy_on_faces(next, proj.nearest) : HUGE_VAL;
      if (bound < proj.energy) {  // kept on the bound: each point's face is still that of proj
        next_proj.nearest = std::move(proj.nearest);
        next_proj.settled = std::move(proj.settled);
        std::fill(next_proj.settled.begin(), next_proj.settled.end(), std::uint8_t(1));
        next_proj.energy = bound;
      } else {
        next_proj = project(next, &proj);
      }
      if (!(next_proj.energy < proj.energy)) break;
      x_ = std::move(next);
      proj = std::move(next_proj);
      ++r.rounds;
      r.vertices_held += held;
      r.rms_after = std::sqrt(proj.energy / pts_.total_weight) * frame_.scale;
    }
    // On x_ as it ends (or, kept on the bound, as the last round found it): where closest_faces starts.
    last_nearest_ = std::move(proj.nearest);
    last_settled_ = std::move(proj.settled);
    // Back to model coordinates; a vertex that did not move keeps its exact input coordinates.
    for (std::size_t v = 0; v < approx_.vertex_count(); ++v) {
      const double *now = &x_[3 * v], *was = &start[3 * v];
      if (now[0] == was[0] && now[1] == was[1] && now[2] == was[2]) continue;
      const Vec3 p = frame_.to_model({now[0], now[1], now[2]});
      double* out = &approx_.positions[3 * v];
      out[0] = p.x, out[1] = p.y, out[2] = p.z;
    }
    return r;
  }

 private:
  // Border vertices: on an edge that only one face has (or more than two), found as the simplifier finds them
  // (core::unique_edges), so that --lock-border holds the same vertices in both.
  void mark_border() {
    for (const core::Edge& e : core::unique_edges(tri_, fixed_.size()))
      if (e.faces != 2) fixed_[e.lo] = fixed_[e.hi] = 1;  // non-manifold edges too: where sheets meet
  }

  // Where each point lands on the approximation with vertices x. The first projection asks a tree
  // of all faces, or, given a vertex near each point (the one `simplify` contracted it into),
  // walks from a face around that vertex to the closest face around the corners of the closest so
  // far. Later ones (`before`: the round before, whose moves are small) look only at the
  // faces around the corners of the point's closest face of then: a fixed set, searched whole, so
  // the answer is the closest of them. A point with neither asks the tree.
  Projection project(const std::vector<double>& x, const Projection* before = nullptr) const {
    const std::size_t count = pts_.weight.size();
    // Where the search for point j starts: the round before's closest face, or the vertex given near j.
    const auto start = [&](std::uint32_t j) { return before ? before->nearest[j] : vertex_near(j); };
    bool need_tree = false;
    for (std::size_t j = 0; j < count && !need_tree; ++j) need_tree = start(std::uint32_t(j)) == UINT32_MAX;
    measure_detail::TriangleBvh tree;
    if (need_tree) {
      std::vector<double> corners(3 * tri_.size());
      for (std::size_t c = 0; c < tri_.size(); ++c)
        for (int k = 0; k < 3; ++k) corners[3 * c + k] = x[3 * tri_[c] + k];
      tree = measure_detail::TriangleBvh(corners);
    }
    Spheres spheres;  // per face: centre and radius, to skip far faces in closest_around
    if (before || !near_vertex_.empty()) spheres = bounding_spheres(x);
    Projection p;
    p.nearest.resize(count);
    p.settled.resize(count);
    p.face.resize(count);
    p.bary.resize(3 * count);
    Projection::Array<double> d2(count);
    core::for_chunks(count, kChunk, core::resolve_threads(opt_.threads),
                     [&](std::size_t, std::size_t begin, std::size_t end) {
                       std::uint32_t hint = UINT32_MAX;  // reset per chunk: never crosses chunks
                       for (std::size_t k = begin; k < end; ++k) {
                         const std::uint32_t j = pts_.order[k];  // each point once (a permutation)
                         p.nearest[j] = p.face[j] = UINT32_MAX, d2[j] = 0;
                         const double* q = &pts_.position[3 * j];
                         const std::uint32_t from = start(j);
                         const auto hit = from == UINT32_MAX ? tree.closest(q, &hint)
                                          : before           ? closest_around(x, spheres, q, from)
                                                             : closest_by_walk(x, spheres, q, from);
                         p.settled[j] = from == UINT32_MAX || (before && hit.triangle == from);
                         if (hit.triangle == UINT32_MAX) continue;
                         p.nearest[j] = hit.triangle;
                         d2[j] = hit.d2;  // counted in the error even when the face cannot pull
                         const std::uint32_t* t = &tri_[3 * std::size_t(hit.triangle)];
                         if (hit.d2 > far_ * far_) continue;  // surface that vanished
                         if (!barycentric({hit.point[0], hit.point[1], hit.point[2]}, at(x, t[0]),
                                          at(x, t[1]), at(x, t[2]), &p.bary[3 * j]))
                           continue;  // a face without area pulls nothing (it cannot be solved for)
                         p.face[j] = hit.triangle;
                       }
                     });
    for (std::size_t j = 0; j < count; ++j) p.energy += pts_.weight[j] * d2[j];  // in point order
    return p;
  }

  // The fit's error with vertices x and each point on face `on` (UINT32_MAX: none, as the
  // projections count it): at least the true one, each point's closest face being at most as far.
  double energy_on_faces(const std::vector<double>& x, std::span<const std::uint32_t> on) const {
    const std::size_t count = pts_.weight.size();
    Projection::Array<double> d2(count);
    core::for_chunks(
        count, kChunk, core::resolve_threads(opt_.threads),
        [&](std::size_t, std::size_t begin, std::size_t end) {
          for (std::size_t j = begin; j < end; ++j) {
            d2[j] = 0;
            if (on[j] == UINT32_MAX) continue;
            const std::uint32_t* t = &tri_[3 * std::size_t(on[j])];
            const double* p = &pts_.position[3 * j];
            const Vec3 q{p[0], p[1], p[2]};
            d2[j] = measure_detail::squared_distance(
                q, measure_detail::closest_point_on_triangle(q, at(x, t[0]), at(x, t[1]), at(x, t[2])));
          }
        });
    double energy = 0;
    for (std::size_t j = 0; j < count; ++j) energy += pts_.weight[j] * d2[j];  // in point order
    return energy;
  }

  // Per face of the approximation with vertices x, a sphere that holds it: centre = the corners'
  // mean, radius = the farthest corner's distance plus 1e-12 (of the diagonal: the frame is
  // normalised), far above the rounding of the distances (~1e-16), so a face the bound skips could
  // never have been the closest; and the face's unit normal (kSphere doubles a face).
  Spheres bounding_spheres(const std::vector<double>& x) const {
    Spheres out(tri_.size() / 3 * kSphere);
    const auto sphere = [&](std::size_t f) {
      const std::uint32_t* t = &tri_[3 * f];
      const Vec3 a = at(x, t[0]), b = at(x, t[1]), c = at(x, t[2]);
      const Vec3 m = (1.0 / 3) * (a + b + c);
      using measure_detail::squared_distance;
      const double r2 = std::max({squared_distance(a, m), squared_distance(b, m), squared_distance(c, m)});
      double* o = &out[kSphere * f];
      o[0] = m.x, o[1] = m.y, o[2] = m.z, o[3] = std::sqrt(r2) + 1e-12;
      // The unit normal, where its direction is known to ~1e-10 (the sine of the face's sharpest
      // angle at least 1e-6); else zero, and closest_around uses the sphere alone.
      const Vec3 e1 = b - a, e2 = c - a, n = cross(e1, e2);
      const double nn = dot(n, n), ee = dot(e1, e1) * dot(e2, e2);
      const double scale = nn > 1e-12 * ee && nn > 0 ? 1 / std::sqrt(nn) : 0.0;
      o[4] = n.x * scale, o[5] = n.y * scale, o[6] = n.z * scale;
    };
    core::for_chunks(tri_.size() / 3, kChunk, core::resolve_threads(opt_.threads),
                     [&](std::size_t, std::size_t begin, std::size_t end) {
                       for (std::size_t f = begin; f < end; ++f) sphere(f);
                     });
    return out;
  }

  // The closest point to q of the faces around the corners of face f (f among them). f goes first
  // (the moves of a round are small, so it is usually still the closest); after it, a face whose
  // bounding sphere lies farther away than the closest point so far cannot be closer and is
  // skipped: the answer of testing every face, for a fraction of the point-triangle tests.
  measure_detail::TriangleBvh::Hit closest_around(const std::vector<double>& x,
                                                  const Spheres& spheres, const double* q,
                                                  std::uint32_t f) const {
    measure_detail::TriangleBvh::Hit hit;
    double reach = HUGE_VAL;  // sqrt(hit.d2)
    const Vec3 point{q[0], q[1], q[2]};
    const auto test = [&](std::uint32_t g) {
      const double* s = &spheres[kSphere * std::size_t(g)];
      const double gap = reach + s[3];
      const Vec3 qc = point - Vec3{s[0], s[1], s[2]};
      const double qc2 = dot(qc, qc);
      if (qc2 > gap * gap) return;
      // Tighter: the face lies in its plane, within s[3] of the centre, so its distance is at least
      // sqrt(h^2 + max(0, l - s[3])^2), h the height over the plane and l the distance along it.
      // Skipped only when that exceeds the closest so far by more than the rounding of h and l
      // (the normal's direction to 1e-10, the frame's coordinates of order 1): never a face that
      // could be as close.
      const double h = qc.x * s[4] + qc.y * s[5] + qc.z * s[6];
      const Vec3 along = qc - h * Vec3{s[4], s[5], s[6]};
      const double l = std::sqrt(dot(along, along)), lateral = l > s[3] ? l - s[3] : 0.0;
      const double bound = reach + 1e-12 + 1e-9 * std::sqrt(qc2);
      if (h * h + lateral * lateral > bound * bound) return;
      const std::uint32_t* t = &tri_[3 * std::size_t(g)];
      const Vec3 c = measure_detail::closest_point_on_triangle(point, at(x, t[0]), at(x, t[1]), at(x, t[2]));
      const double d2 = measure_detail::squared_distance(point, c);
      if (!(d2 < hit.d2 || (d2 == hit.d2 && g < hit.triangle))) return;  // ties: the lowest face, as the tree
      hit.d2 = d2, hit.triangle = g, hit.point[0] = c.x, hit.point[1] = c.y, hit.point[2] = c.z;
      reach = std::sqrt(d2);
    };
    test(f);
    for (std::uint32_t i = around_start_[f]; i < around_start_[f + 1]; ++i) test(around_faces_[i]);
    return hit;
  }

  // Per face f, the other faces around its corners, each once, in the order of the corners' rings
  // (CSR in around_start_, around_faces_): what closest_around tests after f. The faces do not
  // change between rounds, so the lists are made once, not for every query.
  void make_around() {
    // In fixed chunks of faces on the threads, each chunk's lists side by side and then copied to
    // their place: the same lists as one pass over the faces, which on a multi-million-face output
    // was a serial stretch (and its fresh pages) beside the parallel projections.
    const std::size_t nf = tri_.size() / 3;
    constexpr std::size_t kFaces = std::size_t(1) << 13;
    const unsigned threads = core::resolve_threads(opt_.threads);
    std::vector<std::vector<std::uint32_t>> part((nf + kFaces - 1) / kFaces);
    around_start_.resize(nf + 1);
    around_start_[0] = 0;
    core::for_chunks(nf, kFaces, threads, [&](std::size_t chunk, std::size_t begin, std::size_t end) {
      std::vector<std::uint32_t>& out = part[chunk];
      out.reserve(12 * (end - begin));
      for (std::size_t f = begin; f < end; ++f) {
        const std::uint32_t* corners = &tri_[3 * f];
        for (int corner = 0; corner < 3; ++corner) {
          const std::uint32_t v = corners[corner];
          for (std::uint32_t i = ring_start_[v]; i < ring_start_[v + 1]; ++i) {
            const std::uint32_t g = ring_faces_[i];
            const std::uint32_t* t = &tri_[3 * std::size_t(g)];
            // A face around an earlier corner too is listed there.
            const auto has = [t](std::uint32_t u) { return t[0] == u || t[1] == u || t[2] == u; };
            if (g == f || (corner > 0 && has(corners[0])) || (corner > 1 && has(corners[1]))) continue;
            out.push_back(g);
          }
        }
        around_start_[f + 1] = std::uint32_t(out.size());  // within the chunk, until offset below
      }
    });
    std::vector<std::size_t> offset(part.size() + 1, 0);
    for (std::size_t c = 0; c < part.size(); ++c) offset[c + 1] = offset[c] + part[c].size();
    around_faces_.resize(offset.back());
    core::for_chunks(part.size(), 1, threads, [&](std::size_t c, std::size_t, std::size_t) {
      std::copy(part[c].begin(), part[c].end(), around_faces_.begin() + std::ptrdiff_t(offset[c]));
      for (std::size_t f = c * kFaces; f < std::min(nf, (c + 1) * kFaces); ++f)
        around_start_[f + 1] += std::uint32_t(offset[c]);
      std::vector<std::uint32_t>().swap(part[c]);
    });
  }

  // The vertex given near point j, if it has a face; else UINT32_MAX.
  std::uint32_t vertex_near(std::uint32_t j) const { return vertex_of_source(pts_.source[j]); }
  // The vertex given near input point `source`, if it has a face; else UINT32_MAX.
  std::uint32_t vertex_of_source(std::uint32_t source) const {
    if (source >= near_vertex_.size()) return UINT32_MAX;
    const std::uint32_t v = near_vertex_[source];
    if (v >= approx_.vertex_count() || ring_start_[v] == ring_start_[v + 1]) return UINT32_MAX;
    return v;
  }

  // From the face around v whose centre is nearest q, to the closest face around the corners of
  // the closest face so far, until that stays (each step only gets closer, or as close and of a
  // lower index: the face it starts from is among those tested). The input vertices contracted
  // into v lie on its faces or their neighbours', so the walk is a step or two; the cap only
  // bounds a pathological case. It ends in a local minimum: the tree's answer unless a closer face
  // lies beyond a farther one (never, on the benchmark meshes: docs/benchmarks.md).
  measure_detail::TriangleBvh::Hit closest_by_walk(const std::vector<double>& x,
                                                   const Spheres& spheres, const double* q,
                                                   std::uint32_t v) const {
    std::uint32_t f = UINT32_MAX;
    double nearest = HUGE_VAL;
    for (std::uint32_t i = ring_start_[v]; i < ring_start_[v + 1]; ++i) {
      const std::uint32_t g = ring_faces_[i];
      const double* s = &spheres[kSphere * std::size_t(g)];
      const double d2 = measure_detail::squared_distance({q[0], q[1], q[2]}, {s[0], s[1], s[2]});
      if (d2 < nearest) nearest = d2, f = g;
    }
    return walk_from(x, spheres, q, f);
  }
  // From face f to the closest face around the corners of the closest so far, until that stays.
  measure_detail::TriangleBvh::Hit walk_from(const std::vector<double>& x, const Spheres& spheres,
                                             const double* q, std::uint32_t f) const {
    auto hit = closest_around(x, spheres, q, f);
    for (int step = 0; step < 64 && hit.triangle != f && hit.triangle != UINT32_MAX; ++step) {
      f = hit.triangle;
      hit = closest_around(x, spheres, q, f);
    }
    return hit;
  }

 public:
  // After run(): per point of `all` (the points given to refit_to_points, of which the refit's
  // may be a thinned sample), its closest face of the approximation as it ends, walked to from
  // the point's own last projection (when the refit fitted every point; that face itself where
  // its search ended where it began) or, as the first projection does, from the vertex the point
  // went into; UINT32_MAX where neither is known. (A walk from the last answer of the point's run
  // in the Morton order was cheaper, but a run can reach across a fold: on the bunny to 1 % one
  // ended 0.25 of the diagonal from the answer.)
  std::vector<std::uint32_t> closest_faces(const FitPoints& all) const {
    std::vector<std::uint32_t> out(all.weight.size(), UINT32_MAX);
    if (!ready_) return out;
    const bool own = &all == &pts_ && last_nearest_.size() == out.size();
    // The spheres only where a point walks (none when every point's last face is settled).
    bool walks = !own;
    for (std::size_t j = 0; j < out.size() && !walks; ++j)
      walks = !last_settled_[j] || last_nearest_[j] == UINT32_MAX;
    const Spheres spheres = walks ? bounding_spheres(x_) : Spheres{};
    core::for_chunks(out.size(), kChunk, core::resolve_threads(opt_.threads),
                     [&](std::size_t, std::size_t begin, std::size_t end) {
                       for (std::size_t k = begin; k < end; ++k) {
                         const std::uint32_t j = all.order[k];
                         const double* q = &all.position[3 * j];
                         if (own && last_nearest_[j] != UINT32_MAX) {
                           out[j] = last_settled_[j] ? last_nearest_[j]
                                                     : walk_from(x_, spheres, q, last_nearest_[j]).triangle;
                           continue;
                         }
                         const std::uint32_t v = vertex_of_source(all.source[j]);
                         if (v != UINT32_MAX) out[j] = closest_by_walk(x_, spheres, q, v).triangle;
                       }
                     });
    return out;
  }

 private:
  // The least squares problem of one round, for all three coordinates at once (same matrix).
  bool solve(const Projection& proj, std::vector<double>& next) const {
    const std::size_t n = approx_.vertex_count(), nf = tri_.size() / 3;
    // Per face, the 3x3 block sum_i w_i b_i b_i^T, each corner's row stored at the corner's place
    // in its vertex's ring (so that the matrix below reads them in order); per vertex,
    // sum_i w_i b_i p_i.
    const unsigned threads = core::resolve_threads(opt_.threads);
    core::UnzeroedVector<double> block = core::filled(9 * nf, 0.0, threads), rhs = core::filled(3 * n, 0.0, threads),
                                 data = core::filled(n, 0.0, threads);
    const auto block_row = [&](std::size_t f, int r) {
      return &block[3 * std::size_t(ring_slot_[3 * f + r])];
    };
    for (std::size_t j = 0; j < pts_.weight.size(); ++j) {
      const std::uint32_t f = proj.face[j];
      if (f == UINT32_MAX) continue;
      const double* b = &proj.bary[3 * j];
      const double w = pts_.weight[j];
      for (int r = 0; r < 3; ++r) {
        const std::uint32_t v = tri_[3 * std::size_t(f) + r];
        double* row = block_row(f, r);
        for (int c = 0; c < 3; ++c) row[c] += w * b[r] * b[c];
        for (int k = 0; k < 3; ++k) rhs[3 * v + k] += w * b[r] * pts_.position[3 * j + k];
        data[v] += w * b[r] * b[r];
      }
    }
    double mean = 0;
    std::size_t with_data = 0;
    for (std::size_t v = 0; v < n; ++v)
      if (data[v] > 0 && !fixed_[v]) mean += data[v], ++with_data;
    if (with_data == 0) return false;
    mean /= double(with_data);

    // The membrane on the displacement: per face edge (r, c), kappa |(X_r - X_c) - (old_r - old_c)|^2
    // (an interior edge has two faces, so it counts twice and a border edge once).
    const double kappa = kMembrane * mean;
    for (std::size_t f = 0; f < nf; ++f)
      for (int r = 0; r < 3; ++r) {
        const int c = (r + 1) % 3;
        const std::uint32_t vr = tri_[3 * f + r], vc = tri_[3 * f + c];
        block_row(f, r)[r] += kappa, block_row(f, c)[c] += kappa;
        block_row(f, r)[c] -= kappa, block_row(f, c)[r] -= kappa;
        for (int k = 0; k < 3; ++k) {
          const double d = x_[3 * vr + k] - x_[3 * vc + k];
          rhs[3 * vr + k] += kappa * d, rhs[3 * vc + k] -= kappa * d;
        }
      }
    // The matrix, row by row: for each face around the row's vertex (in the ring's order: by
    // face), that vertex's row of the face's block. Fixed vertices are eliminated: their row is
    // the identity, their column moves to the rhs. A row reads and writes only its own vertex's
    // entries, so the rows are made in fixed chunks on the threads and joined in chunk order: the
    // matrix of one pass in vertex order, on any number of threads.
    constexpr std::size_t kRowChunk = std::size_t(1) << 14;
    struct Rows {
      std::vector<std::uint32_t> column, end;  // end: each row's end within the chunk's columns
      std::vector<double> value;
    };
    std::vector<Rows> chunk_rows((n + kRowChunk - 1) / kRowChunk);
    SparseRows a;
    a.diagonal.resize(n);
    std::vector<double> b(3 * n);
    core::for_chunks(n, kRowChunk, threads, [&](std::size_t chunk, std::size_t begin, std::size_t end) {
      Rows& out = chunk_rows[chunk];
      out.column.reserve(8 * (end - begin)), out.value.reserve(8 * (end - begin)), out.end.reserve(end - begin);
      std::vector<std::pair<std::uint32_t, double>> row;  // a few columns: found by a scan
      for (std::uint32_t v = std::uint32_t(begin); v < end; ++v) {
        row.clear();
        const auto add = [&](std::uint32_t c, double value) {
          auto it = std::find_if(row.begin(), row.end(), [c](const auto& e) { return e.first == c; });
          if (it == row.end()) it = row.insert(row.end(), {c, 0.0});
          it->second += value;
        };
        for (std::uint32_t i = ring_start_[v]; i < ring_start_[v + 1] && !fixed_[v]; ++i) {
          const std::uint32_t* t = &tri_[3 * std::size_t(ring_faces_[i])];
          for (int c = 0; c < 3; ++c) {
            const double entry = block[3 * std::size_t(i) + c];
            if (entry == 0) continue;
            if (fixed_[t[c]])
              for (int k = 0; k < 3; ++k) rhs[3 * v + k] -= entry * x_[3 * t[c] + k];
            else
              add(t[c], entry);
          }
        }
        // Vertices without data stay put (their row is lambda X = lambda X_old at full weight).
        const double lambda = fixed_[v] ? 1.0 : data[v] > 0 ? kAnchor * mean : mean;
        add(v, lambda);
        std::sort(row.begin(), row.end());
        for (const auto& [c, value] : row) {
          out.column.push_back(c), out.value.push_back(value);
          if (c == v) a.diagonal[v] = value;
        }
        out.end.push_back(std::uint32_t(out.column.size()));
        for (int k = 0; k < 3; ++k)
          b[3 * v + k] = fixed_[v] ? x_[3 * v + k] : rhs[3 * v + k] + lambda * x_[3 * v + k];
      }
    });
    std::vector<std::size_t> offset(chunk_rows.size() + 1, 0);
    for (std::size_t c = 0; c < chunk_rows.size(); ++c) offset[c + 1] = offset[c] + chunk_rows[c].column.size();
    a.start.resize(n + 1);
    a.column.resize(offset.back()), a.value.resize(offset.back());
    core::for_chunks(chunk_rows.size(), 1, threads, [&](std::size_t c, std::size_t, std::size_t) {
      Rows& rows = chunk_rows[c];
      std::copy(rows.column.begin(), rows.column.end(), a.column.begin() + std::ptrdiff_t(offset[c]));
      std::copy(rows.value.begin(), rows.value.end(), a.value.begin() + std::ptrdiff_t(offset[c]));
      for (std::size_t i = 0; i < rows.end.size(); ++i) a.start[c * kRowChunk + i + 1] = std::uint32_t(offset[c] + rows.end[i]);
      rows = Rows();
    });
    next = x_;  // the guess: where the vertices are
    conjugate_gradients(a, b, next, threads);
    for (std::size_t v = 0; v < n; ++v)
      for (int k = 0; k < 3; ++k)
        if (fixed_[v] || !std::isfinite(next[3 * v + k])) next[3 * v + k] = x_[3 * v + k];
    return true;
  }

  // The largest distance to the original over the vertices and face centroids of x. Leaves in
  // guard_face_ a face of the original near each sample (the closest, where it was searched for),
  // where the guard's searches start.
  double largest_distance(const std::vector<double>& x) {
    const std::size_t n = approx_.vertex_count(), nf = tri_.size() / 3;
    std::vector<double> most(n + nf, 0.0);
    guard_face_.assign(n + nf, UINT32_MAX);
    core::for_chunks(n + nf, kChunk, core::resolve_threads(opt_.threads),
                     [&](std::size_t, std::size_t begin, std::size_t end) {
                       std::uint32_t last = UINT32_MAX;  // the chunk's last answer
                       double most_here = 0;             // of this chunk, so far
                       for (std::size_t i = begin; i < end; ++i) {
                         const Vec3 p = sample(x, i);
                         double start_distance;
                         std::uint32_t face = start_face(p, i, last, start_distance);
                         // No farther from its start face than the largest so far: it cannot be the largest
                         // (its distance is at most that face's), and the search is skipped.
                         if (face != UINT32_MAX && start_distance <= most_here) {
                           guard_face_[i] = face;
                           continue;
                         }
                         most[i] = surface_->distance(p, &face);
                         guard_face_[i] = last = face;
                         most_here = std::max(most_here, most[i]);
                       }
                     });
    return most.empty() ? 0.0 : *std::max_element(most.begin(), most.end());
  }

  // Where the search of the original for sample i (at p) starts: of a face of the original at an
  // input vertex contracted into the sample's (first) vertex and `last`, the one nearer p
  // (UINT32_MAX: neither), its distance in `d`. A search returns the closest face wherever it
  // starts (ties by index): the start only saves work.
  std::uint32_t start_face(const Vec3& p, std::size_t i, std::uint32_t last, double& d) const {
    const std::size_t n = approx_.vertex_count();
    const std::uint32_t v = i < n ? std::uint32_t(i) : tri_[3 * (i - n)];
    std::uint32_t face = last;
    d = face == UINT32_MAX ? HUGE_VAL : surface_->distance_to(p, face);
    const std::uint32_t near = v < original_face_near_.size() ? original_face_near_[v] : UINT32_MAX;
    if (near != UINT32_MAX && near != face) {
      const double dn = surface_->distance_to(p, near);
      if (dn < d) d = dn, face = near;
    }
    return face;
  }

  // Sample i of x: vertex i, or the centroid of face i - vertex count.
  Vec3 sample(const std::vector<double>& x, std::size_t i) const {
    const std::size_t n = approx_.vertex_count();
    if (i < n) return at(x, std::uint32_t(i));
    const std::uint32_t* t = &tri_[3 * (i - n)];
    return (1.0 / 3) * (at(x, t[0]) + at(x, t[1]) + at(x, t[2]));
  }

  // Undoes the moves that take a vertex or a face centroid farther from the original than limit_,
  // or a face out of max_distance, until none does (each sweep that finds one undoes at least one
  // move). Returns the vertices held.
  std::size_t hold_far_from_original(std::vector<double>& next) {
    const std::size_t n = approx_.vertex_count(), nf = tri_.size() / 3;
    const auto moved = [&](std::uint32_t v) {
      return next[3 * v] != x_[3 * v] || next[3 * v + 1] != x_[3 * v + 1] || next[3 * v + 2] != x_[3 * v + 2];
    };
    std::size_t count = 0;
    std::vector<std::uint8_t> bad(n + nf);
    for (bool again = true; again;) {
      again = false;
      core::for_chunks(n + nf, kChunk, core::resolve_threads(opt_.threads),
                       [&](std::size_t, std::size_t begin, std::size_t end) {
                         for (std::size_t i = begin; i < end; ++i) {
                           bad[i] = 0;
                           const std::uint32_t* t = i < n ? nullptr : &tri_[3 * (i - n)];
                           if (t ? !(moved(t[0]) || moved(t[1]) || moved(t[2])) : !moved(std::uint32_t(i)))
                             continue;
                           // The search starts at the sample's face from before the move (moves are small).
                           std::uint32_t& face = guard_face_[i];
                           bad[i] = !surface_->within(sample(next, i), limit_, face) ||
                                    (t && std::isfinite(max_distance_) &&
                                     !surface_->triangle_within(at(next, t[0]), at(next, t[1]),
                                                                at(next, t[2]), max_distance_));
                         }
                       });
      const auto undo = [&](std::uint32_t v) {
        if (!moved(v)) return;
        for (int k = 0; k < 3; ++k) next[3 * v + k] = x_[3 * v + k];
        ++count, again = true;
      };
      for (std::size_t i = 0; i < n + nf; ++i) {
        if (!bad[i]) continue;
        if (i < n) {
          undo(std::uint32_t(i));
        } else {
          for (int k = 0; k < 3; ++k) undo(tri_[3 * (i - n) + k]);
        }
      }
    }
    return count;
  }

  // Undoes the moves of the vertices of every face that turned too far, until none does. Ends:
  // each sweep that finds a face undoes at least one move, and with every move undone nothing turns.
  std::size_t hold_turned_faces(std::vector<double>& next) const {
    const double cos_limit = std::cos(opt_.max_normal_turn_degrees * std::numbers::pi / 180);
    std::vector<std::uint8_t> held(approx_.vertex_count(), 0);
    std::size_t count = 0;
    for (bool again = true; again;) {
      again = false;
      for (std::size_t f = 0; f < tri_.size(); f += 3) {
        const std::uint32_t* t = &tri_[f];
        const Vec3 before = face_normal(x_, t), after = face_normal(next, t);
        const double bb = dot(before, before), aa = dot(after, after);
        if (!(bb > 0)) continue;  // no area before: no direction to keep
        if (dot(before, after) > cos_limit * std::sqrt(bb * aa)) continue;
        for (int k = 0; k < 3; ++k) {
          if (held[t[k]]) continue;
          held[t[k]] = 1, ++count, again = true;
          for (int c = 0; c < 3; ++c) next[3 * t[k] + c] = x_[3 * t[k] + c];
        }
      }
    }
    return count;
  }

  Mesh& approx_;
  const RefitOptions& opt_;
  const std::vector<std::uint32_t>& tri_;
  const FitPoints& pts_;
  std::span<const std::uint32_t> near_vertex_;
  const Frame frame_;      // of the points: x_ = frame_.to_frame(approx_'s positions)
  const core::SurfaceDistance* surface_;  // the original, in frame_ (null: no distance guard)
  std::vector<std::uint32_t> original_face_near_;  // per vertex: a face of surface_ near it, or UINT32_MAX
  std::vector<std::uint32_t> guard_face_;  // per sample (largest_distance): where its next search starts
  const double max_distance_;             // RefitOptions::max_distance in frame_
  double limit_ = HUGE_VAL;               // a sample may not move farther than this from the original
  double far_ = HUGE_VAL;                 // a point farther than this from the approximation pulls nothing
  std::vector<double> x_;  // approximation vertices, normalised
  std::vector<std::uint8_t> fixed_;
  std::vector<std::uint32_t> ring_start_, ring_faces_;  // faces around each vertex
  std::vector<std::uint32_t> ring_slot_;  // per corner of a face: its place in its vertex's ring
  std::vector<std::uint32_t> around_start_;  // per face: the faces around its corners (CSR)
  core::UnzeroedVector<std::uint32_t> around_faces_;
  Projection::Array<std::uint32_t> last_nearest_;  // per point: its closest face at the end of run()
  Projection::Array<std::uint8_t> last_settled_;   // per point: whether a walk from there would stay
  bool ready_ = false;
};

}  // namespace

std::vector<double> vertex_areas(MeshView mesh, unsigned threads) {
  // Each vertex's sum runs over its faces in face order, whatever the threads: a thread owns a
  // range of vertices and reads every face, but computes and adds only the faces with a corner in
  // its range (on a mesh whose vertex order follows its surface, its own share of the faces and a
  // few along the range's edges). So the result is the serial one, bit for bit.
  const std::size_t nv = mesh.vertex_count();
  std::vector<double> area(nv, 0.0);
  core::for_vertex_ranges(nv, threads, 65536, [&](std::size_t lo, std::size_t hi) {
    const auto mine = [&](std::uint32_t v) { return v >= lo && v < hi; };
    for (std::size_t f = 0; f < mesh.indices.size(); f += 3) {
      const std::uint32_t* t = &mesh.indices[f];
      if (!(mine(t[0]) || mine(t[1]) || mine(t[2]))) continue;
      const auto p = [&](int k) {
        const double* q = &mesh.positions[3 * std::size_t(t[k])];
        return Vec3{q[0], q[1], q[2]};
      };
      const Vec3 n = cross(p(1) - p(0), p(2) - p(0));
      const double third = std::sqrt(dot(n, n)) / 6;  // a third of half the cross product
      if (!std::isfinite(third)) continue;
      for (int k = 0; k < 3; ++k)
        if (mine(t[k])) area[t[k]] += third;
    }
  });
  return area;
}

void check_options(const RefitOptions& options) {
  if (!(options.max_normal_turn_degrees > 0 && options.max_normal_turn_degrees < 180))
    throw Error("refit: the face turn limit must be between 0 and 180 degrees");
  if (!(options.points_per_vertex >= 0 && std::isfinite(options.points_per_vertex)))
    throw Error("refit: the points per vertex must be 0 (all) or a positive number");
}

core::SurfaceDistance surface_in_frame(std::span<const double> positions, std::span<const std::uint32_t> indices,
                                       const Frame& frame, unsigned threads) {
  // The tree keeps the vertices mapped into the frame and each face's indices (TriangleBvh's
  // indexed form): on a closed mesh a third of the bytes of nine coordinates a face, which were
  // the largest array of a large input's refit and repair (720 MB of 1 GB on a 10M-face input).
  // Mapped on the threads, each vertex as each of its corners was before: the same numbers.
  core::UnzeroedVector<double> vertices(positions.size());
  core::for_chunks(positions.size() / 3, std::size_t(1) << 16, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) {
      const Vec3 q = frame.to_frame({positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]});
      vertices[3 * v] = q.x, vertices[3 * v + 1] = q.y, vertices[3 * v + 2] = q.z;
    }
  });
  // Per vertex, the lowest face that has it: each range's pass over the faces in order sees it
  // first.
  core::SurfaceDistance::FaceAtVertex face_at(positions.size() / 3);
  core::for_vertex_ranges(face_at.size(), threads, 65536, [&](std::size_t lo, std::size_t hi) {
    std::fill(face_at.begin() + std::ptrdiff_t(lo), face_at.begin() + std::ptrdiff_t(hi), UINT32_MAX);
    for (std::size_t c = 0; c < indices.size(); ++c) {
      const std::uint32_t v = indices[c];
      if (v >= lo && v < hi && face_at[v] == UINT32_MAX) face_at[v] = std::uint32_t(c / 3);
    }
  });
  return core::SurfaceDistance(std::move(vertices), indices, std::move(face_at), threads);
}

RefitResult refit_to_points(const FitPoints& points, Mesh& approx, const RefitOptions& options,
                            std::span<const std::uint32_t> near_vertex, const core::SurfaceDistance* surface,
                            std::vector<std::uint32_t>* closest_faces) {
  // points_per_vertex: one point for each run of `group` (fewer than one point wanted: one run).
  const double wanted = options.points_per_vertex * double(approx.vertex_count());
  const std::size_t n = points.weight.size();
  std::size_t group = 0;  // 0 or 1: every point
  if (wanted > 0) group = wanted <= 1 ? n : std::size_t(double(n) / wanted);
  const FitPoints sample = group >= 2 ? points.thinned(group, core::resolve_threads(options.threads)) : FitPoints{};
  Refitter refitter(group >= 2 ? sample : points, approx, options, near_vertex, surface);
  const RefitResult result = refitter.run(closest_faces != nullptr);
  if (closest_faces) *closest_faces = refitter.closest_faces(points);
  return result;
}

}  // namespace refit_detail

std::vector<RefitResult> refit(MeshView original, std::span<Mesh* const> approximations,
                               const RefitOptions& options) {
  // Everything is checked before anything moves.
  refit_detail::check_options(options);
  check_mesh(original, "original");
  for (const Mesh* approx : approximations) check_mesh(*approx, "approximation");
  const std::vector<double> weights = refit_detail::vertex_areas(original);
  const refit_detail::FitPoints points(original.positions, weights);
  const core::SurfaceDistance surface =
      refit_detail::surface_in_frame(original.positions, original.indices, points.frame());
  std::vector<RefitResult> results;
  for (Mesh* approx : approximations)
    results.push_back(refit_detail::refit_to_points(points, *approx, options, {}, &surface));
  return results;
}

RefitResult refit(MeshView original, Mesh& approx, const RefitOptions& options) {
  Mesh* one[] = {&approx};
  return refit(original, one, options).front();
}

}  // namespace qem
