#include "core/far_repair.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <numbers>
#include <vector>

#include "core/parallel_chunks.h"
#include "measure/bvh.h"
#include "measure/point_triangle.h"

namespace qem::core {

namespace {

// Queries per work item (fixed: the results never depend on the threads).
constexpr std::size_t kChunk = 1024;
// The sample grid on a face: barycentric, kGrid subdivisions per edge (15 points at 4), which puts
// points at the middle of each edge, where an edge across a groove is farthest from it.
constexpr int kGrid = 4;
constexpr int kSamples = (kGrid + 1) * (kGrid + 2) / 2;

// The grid's points as weights (u, v) of b - a and c - a, those of edge bc first, its middle
// first: a flip's new faces have the new edge there, where they are farthest from the input if
// anywhere, so a flip that would not help is usually refused after one sample.
struct SampleAt {
  double u, v;
};
constexpr std::array<SampleAt, kSamples> sample_order() {
  std::array<SampleAt, kSamples> order{};
  int n = 0;
  const int edge[] = {kGrid / 2, kGrid / 2 - 1, kGrid / 2 + 1, 0, kGrid};  // i along bc, middle out
  for (int i : edge) order[n++] = {double(i) / kGrid, double(kGrid - i) / kGrid};
  for (int i = 0; i <= kGrid; ++i)
    for (int j = 0; i + j < kGrid; ++j) order[n++] = {double(i) / kGrid, double(j) / kGrid};
  return order;
}
constexpr std::array<SampleAt, kSamples> kOrder = sample_order();
static_assert(kGrid == 4, "the edge's points in sample_order are written out for 4 subdivisions");

// What a face contributes: its samples' largest and summed squared distances to the input (the
// sum times the face's area over the sample count: its side of GH97 §6.1's E).
struct FaceScore {
  double most = 0;    // largest sample distance
  double energy = 0;  // area * mean squared sample distance (complete only when all were taken)
  std::uint32_t hint = UINT32_MAX;  // a face of the input near the face, where searches start
};

class Repairer {
 public:
  Repairer(Mesh& approx, const Frame& frame, const SurfaceDistance& surface, std::span<const double> points,
          std::span<const double> weights, const FarRepairOptions& options)
      : mesh_(approx), frame_(frame), surface_(surface), points_(points), weights_(weights), opt_(options),
        cos_turn_(std::cos(options.max_normal_turn_degrees * std::numbers::pi / 180)),
        weight_scale_(1 / (frame.scale * frame.scale)) {
    const std::size_t n = approx.vertex_count();
    x_.resize(n);
    for (std::size_t v = 0; v < n; ++v) {
      const double* p = &approx.positions[3 * v];
      x_[v] = frame.to_frame({p[0], p[1], p[2]});
    }
    tri_ = approx.indices;
    // Vertices at one position (wedges of a seam, or vertices the input never welded) are held:
    // an edge added at one could duplicate an edge of its twin.
    held_.assign(n, 0);
    for (std::size_t v = 0; v < n && v < options.held.size(); ++v) held_[v] = options.held[v];
    std::vector<std::uint32_t> order(n);
    for (std::uint32_t v = 0; v < n; ++v) order[v] = v;
    const auto key = [&](std::uint32_t v) { return std::array<double, 3>{x_[v].x, x_[v].y, x_[v].z}; };
    std::sort(order.begin(), order.end(), [&](std::uint32_t u, std::uint32_t v) { return key(u) < key(v); });
    for (std::size_t i = 1; i < n; ++i)
      if (key(order[i]) == key(order[i - 1])) held_[order[i]] = held_[order[i - 1]] = 1;
    faces_at_.assign(n, {});
    for (std::uint32_t f = 0; f < face_count(); ++f)
      for (int k = 0; k < 3; ++k) faces_at_[tri_[3 * f + k]].push_back(f);
    assign_points();
    scan_faces();
  }

  FarRepairResult run() {
    FarRepairResult r;
    r.largest_before = largest_;
    // The first sweep tries every far face; each later one only the faces a flip of the sweep
    // before changed or bordered (elsewhere nothing changed, so no other flip became possible).
    std::vector<std::uint8_t> dirty(face_count(), 1);
    for (unsigned sweep = 0; sweep < opt_.sweeps; ++sweep) {
      const std::size_t flips = this->sweep(opt_.from_fraction * largest_, dirty);
      r.flips += flips;
      if (flips == 0) break;
    }
    if (opt_.move_vertices) r.moves = move_vertices();
    mesh_.indices = tri_;
    for (std::uint32_t v : moved_) {
      const Vec3 p = frame_.to_model(x_[v]);
      mesh_.positions[3 * std::size_t(v)] = p.x, mesh_.positions[3 * std::size_t(v) + 1] = p.y,
                                 mesh_.positions[3 * std::size_t(v) + 2] = p.z;
    }
    return r;
  }

 private:
  std::uint32_t face_count() const { return std::uint32_t(tri_.size() / 3); }
  Vec3 point(std::uint32_t p) const { return {points_[3 * p], points_[3 * p + 1], points_[3 * p + 2]}; }

  // The samples of face abc, searched from input face `hint`; stops at the first sample at least
  // `limit` from the input (then `energy` is incomplete and `most` at least limit).
  FaceScore score(const Vec3& a, const Vec3& b, const Vec3& c, std::uint32_t hint,
                  double limit = HUGE_VAL) const {
    FaceScore s;
    for (const SampleAt& at : kOrder) {
      const double d = surface_.distance(a + (b - a) * at.u + (c - a) * at.v, &hint);
      s.most = std::max(s.most, d);
      s.energy += d * d;
      if (d >= limit) break;
    }
    s.energy *= 0.5 * length(cross(b - a, c - a)) / kSamples;
    s.hint = hint;
    return s;
  }
  FaceScore score(std::uint32_t f, double limit = HUGE_VAL) const {
    const std::uint32_t* t = &tri_[3 * f];
    return score(x_[t[0]], x_[t[1]], x_[t[2]], hint_[f], limit);
  }
  void ensure_scored(std::uint32_t f) {
    if (scored_[f]) return;
    score_[f] = score(f);
    scored_[f] = 1;
  }

  // Where the far faces are, for a fraction of the samples' searches: per face, the largest
  // distance of its centroid and edge midpoints (the middle of an edge across a groove is where
  // it is farthest from it) to the input (near_), and the largest of those and of the input
  // points' distances (largest_). The exact samples of a face are taken when a flip needs them.
  void scan_faces() {
    const std::size_t nf = face_count();
    near_.assign(nf, 0);
    hint_.assign(nf, UINT32_MAX);
    scored_.assign(nf, 0);
    score_.assign(nf, {});
    for_chunks(nf, kChunk, resolve_threads(opt_.threads), [&](std::size_t, std::size_t begin, std::size_t end) {
      std::uint32_t hint = UINT32_MAX;
      for (std::size_t f = begin; f < end; ++f) {
        const std::uint32_t* t = &tri_[3 * f];
        const Vec3 &a = x_[t[0]], &b = x_[t[1]], &c = x_[t[2]];
        const Vec3 at[4] = {(1.0 / 3) * (a + b + c), 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a)};
        double most = 0;
        for (const Vec3& q : at) most = std::max(most, surface_.distance(q, &hint));
        near_[f] = most;
        hint_[f] = hint;
      }
    });
    largest_ = 0;
    for (std::uint32_t f = 0; f < nf; ++f) largest_ = std::max(largest_, local(f));
  }

  // Each input point goes to its closest output face (of two as close, the lower index): only the
  // points of a flip's two faces can come farther from the output by it.
  void assign_points() {
    std::vector<double> corners(9 * std::size_t(face_count()));
    for (std::size_t f = 0; f < face_count(); ++f)
      for (int k = 0; k < 3; ++k) {
        const Vec3& p = x_[tri_[3 * f + k]];
        corners[9 * f + 3 * k] = p.x, corners[9 * f + 3 * k + 1] = p.y, corners[9 * f + 3 * k + 2] = p.z;
      }
    const measure_detail::TriangleBvh tree(corners, resolve_threads(opt_.threads));
    const std::size_t count = weights_.size();
    std::vector<std::uint32_t> face_of(count);
    d2_.resize(count);
    for_chunks(count, kChunk, resolve_threads(opt_.threads), [&](std::size_t, std::size_t begin, std::size_t end) {
      std::uint32_t hint = UINT32_MAX;
      for (std::size_t p = begin; p < end; ++p) {
        const auto hit = tree.closest(&points_[3 * p], &hint);
        face_of[p] = hit.triangle, d2_[p] = hit.d2;
      }
    });
    points_of_.assign(face_count(), {});
    for (std::uint32_t p = 0; p < count; ++p)
      if (face_of[p] != UINT32_MAX) points_of_[face_of[p]].push_back(p);
    near_most_.assign(face_count(), 0);
    for (std::uint32_t f = 0; f < face_count(); ++f) near_most_[f] = nearest_most(f);
  }

  double nearest_most(std::uint32_t f) const {
    double most = 0;
    for (std::uint32_t p : points_of_[f]) most = std::max(most, d2_[p]);
    return std::sqrt(most);
  }
  // The face's largest distance (both ways): exact once scored, else that of its centroid and
  // edge midpoints.
  double local(std::uint32_t f) const { return std::max(scored_[f] ? score_[f].most : near_[f], near_most_[f]); }

  // The face other than f that has the edge from a to b the other way round, or UINT32_MAX when
  // there is none or more than one (a border or a non-manifold edge), or when a face has it the
  // same way round.
  std::uint32_t across(std::uint32_t f, std::uint32_t a, std::uint32_t b) const {
    std::uint32_t found = UINT32_MAX;
    for (std::uint32_t g : faces_at_[a]) {
      if (g == f) continue;
      const std::uint32_t* t = &tri_[3 * g];
      for (int k = 0; k < 3; ++k) {
        if (t[k] != a) continue;
        if (t[(k + 1) % 3] == b) return UINT32_MAX;  // same way round: not orientable here
        if (t[(k + 2) % 3] == b) {
          if (found != UINT32_MAX) return UINT32_MAX;
          found = g;
        }
      }
    }
    return found;
  }
  bool has_edge(std::uint32_t a, std::uint32_t b) const {
    for (std::uint32_t g : faces_at_[a]) {
      const std::uint32_t* t = &tri_[3 * g];
      if (t[0] == b || t[1] == b || t[2] == b) return true;
    }
    return false;
  }
  bool held(std::uint32_t v) const { return held_[v] != 0; }
  Vec3 normal(std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
    return cross(x_[b] - x_[a], x_[c] - x_[a]);
  }
  // The unit normal of the face across edge ab from f (UINT32_MAX: none, then a zero vector).
  Vec3 across_normal(std::uint32_t f, std::uint32_t a, std::uint32_t b) const {
    const std::uint32_t g = across(f, a, b);
    if (g == UINT32_MAX) return {0, 0, 0};
    const std::uint32_t* t = &tri_[3 * g];
    return normalized(normal(t[0], t[1], t[2]));
  }
  // Whether the crease between unit normals n and m is allowed where it replaces the crease
  // between o and m (a zero m: no neighbour, nothing to check).
  bool crease_ok(const Vec3& n, const Vec3& o, const Vec3& m) const {
    if (dot(m, m) == 0) return true;
    return dot(n, m) >= std::min(cos_turn_, dot(o, m));
  }

  // The largest and the area-weighted squared distances of the input points `pts` to the nearer of
  // faces g1, g2 (corners given).
  void near_points(const std::vector<std::uint32_t>& pts, const Vec3* g1, const Vec3* g2,
                   std::vector<double>& d2, double& most, double& energy) const {
    using measure_detail::closest_point_on_triangle;
    using measure_detail::squared_distance;
    d2.resize(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Vec3 p = point(pts[i]);
      const double one = squared_distance(p, closest_point_on_triangle(p, g1[0], g1[1], g1[2]));
      const double two = squared_distance(p, closest_point_on_triangle(p, g2[0], g2[1], g2[2]));
      d2[i] = std::min(one, two);
      most = std::max(most, d2[i]);
      energy += weights_[pts[i]] * weight_scale_ * d2[i];
    }
  }

  // Tries the flip of edge k of face f1; returns the other face of the flip, or UINT32_MAX when
  // it was not made.
  std::uint32_t try_flip(std::uint32_t f1, int k) {
    const std::uint32_t* t1 = &tri_[3 * f1];
    const std::uint32_t a = t1[k], b = t1[(k + 1) % 3], c = t1[(k + 2) % 3];
    const std::uint32_t f2 = across(f1, a, b);
    if (f2 == UINT32_MAX) return UINT32_MAX;
    if (!mesh_.face_materials.empty() && mesh_.face_materials[f1] != mesh_.face_materials[f2]) return UINT32_MAX;
    const std::uint32_t* t2 = &tri_[3 * f2];
    std::uint32_t d = UINT32_MAX;
    for (int i = 0; i < 3; ++i)
      if (t2[i] != a && t2[i] != b) d = t2[i];
    if (d == UINT32_MAX || d == c || held(a) || held(b) || held(c) || held(d) || has_edge(c, d)) return UINT32_MAX;
    // Orientation and folds: the new faces (a,d,c), (b,c,d) turn the same way as the old ones
    // (each within 90 degrees of both), and no crease round them gets sharper than allowed.
    const Vec3 n1 = normalized(normal(a, b, c)), n2 = normalized(normal(b, a, d));
    const Vec3 m1 = normalized(normal(a, d, c)), m2 = normalized(normal(b, c, d));
    if (dot(m1, m1) == 0 || dot(m2, m2) == 0 || dot(n1, n1) == 0 || dot(n2, n2) == 0) return UINT32_MAX;
    if (dot(m1, n1) <= 0 || dot(m1, n2) <= 0 || dot(m2, n1) <= 0 || dot(m2, n2) <= 0) return UINT32_MAX;
    if (dot(m1, m2) < std::min(cos_turn_, dot(n1, n2))) return UINT32_MAX;
    // The outer edges: c-a was f1's (now g1's), a-d f2's (now g1's), d-b f2's (now g2's), b-c f1's.
    if (!crease_ok(m1, n1, across_normal(f1, c, a)) || !crease_ok(m1, n2, across_normal(f2, a, d)) ||
        !crease_ok(m2, n2, across_normal(f2, d, b)) || !crease_ok(m2, n1, across_normal(f1, b, c)))
      return UINT32_MAX;

    // The local Hausdorff distance and share of E, before and after.
    // (Corners d, c of g1 and c, d of g2 second and third: the new edge's samples go first.)
    ensure_scored(f1), ensure_scored(f2);
    const double old_most = std::max(local(f1), local(f2));
    const Vec3 g1[3] = {x_[a], x_[d], x_[c]}, g2[3] = {x_[b], x_[c], x_[d]};
    const FaceScore s1 = score(g1[0], g1[1], g1[2], score_[f1].hint, old_most);
    if (s1.most >= old_most) return UINT32_MAX;
    const FaceScore s2 = score(g2[0], g2[1], g2[2], score_[f2].hint, old_most);
    if (s2.most >= old_most) return UINT32_MAX;
    double old_energy = score_[f1].energy + score_[f2].energy;
    for (std::uint32_t f : {f1, f2})
      for (std::uint32_t p : points_of_[f]) old_energy += weights_[p] * weight_scale_ * d2_[p];
    std::vector<std::uint32_t>& pts = scratch_points_;
    pts.assign(points_of_[f1].begin(), points_of_[f1].end());
    pts.insert(pts.end(), points_of_[f2].begin(), points_of_[f2].end());
    double most2 = 0, energy = s1.energy + s2.energy;
    near_points(pts, g1, g2, scratch_d2_, most2, energy);
    if (std::max({s1.most, s2.most, std::sqrt(most2)}) >= old_most) return UINT32_MAX;
    if (energy > old_energy * (1 + opt_.error_margin)) return UINT32_MAX;

    // Made: f1 becomes (a,d,c), f2 (b,c,d); b leaves f1 and d joins it, a leaves f2 and c joins it.
    tri_[3 * f1] = a, tri_[3 * f1 + 1] = d, tri_[3 * f1 + 2] = c;
    tri_[3 * f2] = b, tri_[3 * f2 + 1] = c, tri_[3 * f2 + 2] = d;
    std::erase(faces_at_[b], f1), faces_at_[d].push_back(f1);
    std::erase(faces_at_[a], f2), faces_at_[c].push_back(f2);
    score_[f1] = s1, score_[f2] = s2;
    scored_[f1] = scored_[f2] = 1;
    points_of_[f1].clear(), points_of_[f2].clear();
    using measure_detail::closest_point_on_triangle;
    using measure_detail::squared_distance;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Vec3 p = point(pts[i]);
      const double one = squared_distance(p, closest_point_on_triangle(p, g1[0], g1[1], g1[2]));
      d2_[pts[i]] = scratch_d2_[i];
      points_of_[one <= scratch_d2_[i] ? f1 : f2].push_back(pts[i]);
    }
    near_most_[f1] = nearest_most(f1), near_most_[f2] = nearest_most(f2);
    return f2;
  }

  // Whether v is interior: every edge at it has exactly one face on the other side (no border,
  // no non-manifold edge), so a move keeps every border where it was.
  bool interior(std::uint32_t v) const {
    for (std::uint32_t f : faces_at_[v]) {
      const std::uint32_t* t = &tri_[3 * f];
      for (int k = 0; k < 3; ++k)
        if (t[k] == v && (across(f, t[k], t[(k + 1) % 3]) == UINT32_MAX || across(f, t[(k + 2) % 3], t[k]) == UINT32_MAX))
          return false;
    }
    return true;
  }

  // Tries to move v to y: made when the largest distance (both ways) over v's faces falls, their
  // share of E does not rise, and no face turns by more than the limit.
  bool try_move(std::uint32_t v, const Vec3& y) {
    const std::vector<std::uint32_t>& fan = faces_at_[v];
    double old_most = 0, old_energy = 0;
    for (std::uint32_t f : fan) {
      ensure_scored(f);
      old_most = std::max(old_most, local(f));
      old_energy += score_[f].energy;
      for (std::uint32_t p : points_of_[f]) old_energy += weights_[p] * weight_scale_ * d2_[p];
    }
    const Vec3 x = x_[v];
    std::vector<FaceScore> scores(fan.size());
    for (std::size_t i = 0; i < fan.size(); ++i) {
      const std::uint32_t* t = &tri_[3 * fan[i]];
      const Vec3 n = normalized(normal(t[0], t[1], t[2]));
      x_[v] = y;
      const Vec3 m = normalized(normal(t[0], t[1], t[2]));
      if (dot(m, m) == 0 || dot(n, m) < cos_turn_) return x_[v] = x, false;
      scores[i] = score(x_[t[0]], x_[t[1]], x_[t[2]], score_[fan[i]].hint, old_most);
      x_[v] = x;
      if (scores[i].most >= old_most) return false;
    }
    // The fan's points, each to the nearest of the fan's faces after the move.
    std::vector<std::uint32_t>& pts = scratch_points_;
    pts.clear();
    for (std::uint32_t f : fan) pts.insert(pts.end(), points_of_[f].begin(), points_of_[f].end());
    x_[v] = y;
    std::vector<std::uint32_t> nearest(pts.size());
    scratch_d2_.resize(pts.size());
    double most2 = 0, energy = 0;
    for (std::size_t i = 0; i < fan.size(); ++i) energy += scores[i].energy;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Vec3 p = point(pts[i]);
      double best = HUGE_VAL;
      for (std::uint32_t f : fan) {
        const std::uint32_t* t = &tri_[3 * f];
        const double d2 = measure_detail::squared_distance(
            p, measure_detail::closest_point_on_triangle(p, x_[t[0]], x_[t[1]], x_[t[2]]));
        if (d2 < best) best = d2, nearest[i] = f;
      }
      most2 = std::max(most2, best);
      energy += weights_[pts[i]] * weight_scale_ * best;
      scratch_d2_[i] = best;
    }
    if (std::sqrt(most2) >= old_most || energy > old_energy * (1 + opt_.error_margin)) return x_[v] = x, false;
    for (std::size_t i = 0; i < fan.size(); ++i) score_[fan[i]] = scores[i], scored_[fan[i]] = 1, points_of_[fan[i]].clear();
    for (std::size_t i = 0; i < pts.size(); ++i) d2_[pts[i]] = scratch_d2_[i], points_of_[nearest[i]].push_back(pts[i]);
    for (std::uint32_t f : fan) near_most_[f] = nearest_most(f);
    return true;
  }

  // GH97's placement and the refit can leave a small bump of the input cut off by one vertex (the
  // bump's top far from the output next to that vertex): the input points at least from_fraction
  // of the largest distance from the output, farthest first, pull the nearest corner of their
  // face toward them (all the way, or half), where that lowers the local largest distance.
  std::size_t move_vertices() {
    std::vector<std::uint32_t> far;
    const double from = opt_.from_fraction * largest_;
    for (std::uint32_t p = 0; p < d2_.size(); ++p)
      if (std::sqrt(d2_[p]) >= from) far.push_back(p);
    keep_farthest(far, [&](std::uint32_t a, std::uint32_t b) { return d2_[a] > d2_[b] || (d2_[a] == d2_[b] && a < b); });
    std::vector<std::uint32_t> face_of(d2_.size(), UINT32_MAX);
    for (std::uint32_t f = 0; f < face_count(); ++f)
      for (std::uint32_t p : points_of_[f]) face_of[p] = f;
    std::size_t moves = 0;
    for (std::uint32_t p : far) {
      const std::uint32_t f = face_of[p];
      if (f == UINT32_MAX) continue;
      const Vec3 q = point(p);
      const std::uint32_t* t = &tri_[3 * f];
      const Vec3 c = measure_detail::closest_point_on_triangle(q, x_[t[0]], x_[t[1]], x_[t[2]]);
      const std::uint32_t v = move_a_corner(f, c, {1.0, 0.5}, [&](std::uint32_t u, double step) { return x_[u] + (q - c) * step; });
      if (v == UINT32_MAX) continue;
      ++moves;
      // A move hands points only among the faces of the vertex moved.
      for (std::uint32_t g : faces_at_[v])
        for (std::uint32_t r : points_of_[g]) face_of[r] = g;
    }
    return moves + move_toward_input(from);
  }

  // The other way round: a face whose sample is far from the input (the output bulging over a
  // dent, or sagging under a ridge) pushes the corner nearest that sample along the face's normal,
  // either way, by the sample's distance or half of it. The farthest kMovesTried faces only.
  std::size_t move_toward_input(double from) {
    const auto most = [&](std::uint32_t f) { return scored_[f] ? score_[f].most : near_[f]; };
    std::vector<std::uint32_t> far;
    for (std::uint32_t f = 0; f < face_count(); ++f)
      if (most(f) >= from) far.push_back(f);
    keep_farthest(far, [&](std::uint32_t a, std::uint32_t b) { return most(a) > most(b) || (most(a) == most(b) && a < b); });
    std::size_t moves = 0;
    for (std::uint32_t f : far) {
      const std::uint32_t* t = &tri_[3 * f];
      const Vec3 &a = x_[t[0]], &b = x_[t[1]], &c = x_[t[2]];
      // The face's farthest sample.
      std::uint32_t hint = hint_[f];
      double d = 0;
      Vec3 at{};
      for (const SampleAt& w : kOrder) {
        const Vec3 q = a + (b - a) * w.u + (c - a) * w.v;
        const double e = surface_.distance(q, &hint);
        if (e > d) d = e, at = q;
      }
      const Vec3 n = normalized(normal(t[0], t[1], t[2]));
      if (d < from || dot(n, n) == 0) continue;
      moves += move_a_corner(f, at, {1.0, -1.0, 0.5, -0.5},
                             [&](std::uint32_t u, double step) { return x_[u] + n * (d * step); }) != UINT32_MAX;
    }
    return moves;
  }

  // Keeps of `items` the kMovesTried first by `farther` (a strict order, farthest first), sorted:
  // the largest distance is won or lost at the top, and at coarse targets a fraction of the
  // largest takes in a large share of the input's points or the output's faces.
  template <class Farther>
  static void keep_farthest(std::vector<std::uint32_t>& items, Farther farther) {
    constexpr std::size_t kMovesTried = 64;
    if (items.size() > kMovesTried) {
      std::nth_element(items.begin(), items.begin() + kMovesTried, items.end(), farther);
      items.resize(kMovesTried);
    }
    std::sort(items.begin(), items.end(), farther);
  }

  // Moves a corner of face f, the one nearest `near` first, to the first position `to(corner,
  // step)` over `steps` that try_move accepts; held and non-interior corners stay. Returns the
  // corner moved, or UINT32_MAX.
  template <class Target>
  std::uint32_t move_a_corner(std::uint32_t f, const Vec3& near, std::initializer_list<double> steps, Target to) {
    const std::uint32_t* t = &tri_[3 * f];
    std::array<std::uint32_t, 3> corners = {t[0], t[1], t[2]};
    std::sort(corners.begin(), corners.end(), [&](std::uint32_t a, std::uint32_t b) {
      const double da = measure_detail::squared_distance(near, x_[a]), db = measure_detail::squared_distance(near, x_[b]);
      return da < db || (da == db && a < b);
    });
    for (std::uint32_t v : corners) {
      if (held(v) || !interior(v)) continue;
      for (double step : steps)
        if (try_move(v, to(v, step))) {
          note_moved(v);
          return v;
        }
    }
    return UINT32_MAX;
  }

  void note_moved(std::uint32_t v) {
    if (!std::binary_search(moved_.begin(), moved_.end(), v)) moved_.insert(std::lower_bound(moved_.begin(), moved_.end(), v), v);
  }

  // One sweep over the edges of the faces marked in `dirty` that are at least `from` from the
  // input (locally), in face order. Leaves in `dirty` the faces of this sweep's flips and their
  // neighbours.
  std::size_t sweep(double from, std::vector<std::uint8_t>& dirty) {
    std::vector<std::uint32_t> far;
    for (std::uint32_t f = 0; f < face_count(); ++f) {
      if (!dirty[f] || local(f) < from) continue;
      ensure_scored(f);
      if (local(f) >= from) far.push_back(f);
    }
    std::fill(dirty.begin(), dirty.end(), 0);
    std::size_t flips = 0;
    for (std::uint32_t f : far)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t g = try_flip(f, k);
        if (g == UINT32_MAX) continue;
        ++flips;
        for (std::uint32_t h : {f, g}) {
          dirty[h] = 1;
          for (int e = 0; e < 3; ++e) {
            const std::uint32_t next = across(h, tri_[3 * h + e], tri_[3 * h + (e + 1) % 3]);
            if (next != UINT32_MAX) dirty[next] = 1;
          }
        }
        break;  // f is another face now
      }
    return flips;
  }

  Mesh& mesh_;
  const Frame frame_;
  const SurfaceDistance& surface_;
  std::span<const double> points_, weights_;
  const FarRepairOptions& opt_;
  const double cos_turn_;
  const double weight_scale_;  // model area to the frame's
  std::vector<Vec3> x_;                              // output positions in the frame
  std::vector<std::uint8_t> held_;                   // per vertex: its edges stay
  std::vector<std::uint32_t> tri_;                   // output faces (3 per face), flipped in place
  std::vector<std::vector<std::uint32_t>> faces_at_;  // per vertex, the faces that have it
  std::vector<FaceScore> score_;                     // per face, its samples (where scored_)
  std::vector<std::uint8_t> scored_;                 // per face: score_ is exact
  std::vector<double> near_;                         // per face, its centroid's and edge midpoints' largest
  std::vector<std::uint32_t> hint_;                  // per face, a face of the input near it
  double largest_ = 0;                               // the largest distance both ways, at the start (scanned)
  std::vector<std::vector<std::uint32_t>> points_of_;  // per face, the input points closest to it
  std::vector<double> near_most_;                    // per face, the largest of those points' distances
  std::vector<double> d2_;                           // per point, its squared distance to its face
  std::vector<std::uint32_t> moved_;                 // vertices moved (ascending, once each)
  std::vector<std::uint32_t> scratch_points_;
  std::vector<double> scratch_d2_;
};

}  // namespace

FarRepairResult repair_far_places(Mesh& approx, const Frame& frame, const SurfaceDistance& surface,
                              std::span<const double> points, std::span<const double> weights,
                              const FarRepairOptions& options) {
  if (approx.face_count() < 2 || surface.empty()) return {};
  return Repairer(approx, frame, surface, points, weights, options).run();
}

}  // namespace qem::core
