#include "core/far_repair.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <initializer_list>
#include <iterator>
#include <numbers>
#include <queue>
#include <unordered_map>
#include <vector>

#include "core/attribute_weight.h"
#include "core/border_placement.h"
#include "core/parallel_chunks.h"
#include "core/same_position.h"
#include "core/valid_pairs.h"
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

// A triangle with its box, for asking whether it lies within a distance of a point: a triangle
// whose box is farther is not. The box is widened by a margin far beyond the rounding of the
// closest point on the triangle (relative 1e-9 of its coordinates), so skipping by it never
// changes an answer that closest_point_on_triangle would give.
struct BoxedTriangle {
  Vec3 a, b, c, lo, hi;
  static BoxedTriangle of(const Vec3& a, const Vec3& b, const Vec3& c) {
    const double size = std::max({std::abs(a.x), std::abs(a.y), std::abs(a.z), std::abs(b.x), std::abs(b.y),
                                  std::abs(b.z), std::abs(c.x), std::abs(c.y), std::abs(c.z)});
    const double margin = 1e-9 * size;
    return {a,
            b,
            c,
            {std::min({a.x, b.x, c.x}) - margin, std::min({a.y, b.y, c.y}) - margin,
             std::min({a.z, b.z, c.z}) - margin},
            {std::max({a.x, b.x, c.x}) + margin, std::max({a.y, b.y, c.y}) + margin,
             std::max({a.z, b.z, c.z}) + margin}};
  }
  /// The squared distance from q to the box (0 inside it).
  double box_distance2(const Vec3& q) const {
    const double dx = std::max({lo.x - q.x, q.x - hi.x, 0.0}), dy = std::max({lo.y - q.y, q.y - hi.y, 0.0}),
                 dz = std::max({lo.z - q.z, q.z - hi.z, 0.0});
    return dx * dx + dy * dy + dz * dz;
  }
};

// What a face contributes: its samples' largest and summed squared distances to the input (the
// sum times the face's area over the sample count: its side of GH97 §6.1's E).
struct FaceScore {
  double most = 0;    // largest sample distance
  double energy = 0;  // area * mean squared sample distance (complete only when all were taken)
  std::uint32_t hint = UINT32_MAX;  // a face of the input near the face, where searches start
  double u = 0, v = 0;              // where the largest is (weights of b - a and c - a)
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
    twin_.assign(n, UINT32_MAX);
    caller_held_ = held_;
    alike_.assign(n, UINT32_MAX);
    // Vertices at one place: the sides of a seam or crack the input never welded.
    const std::vector<std::uint32_t> first = first_at_same_position(MeshView(approx), resolve_threads(options.threads));
    for (std::uint32_t v = 0; v < n; ++v) {
      if (first[v] == v) continue;
      if (alike_[first[v]] == UINT32_MAX) {
        alike_[first[v]] = std::uint32_t(places_.size());
        places_.push_back({first[v]});
      }
      alike_[v] = alike_[first[v]];
      places_[alike_[v]].push_back(v);
    }
    for (const std::vector<std::uint32_t>& place : places_) {
      for (std::uint32_t v : place) held_[v] = 1;
      // A pair, neither held by the caller: a crack's two sides (relocations split both together).
      const std::uint32_t a = place[0], b = place[1];
      if (place.size() == 2 && !caller_held_[a] && !caller_held_[b]) twin_[a] = b, twin_[b] = a;
    }
    // The channels that count in the metric, where the output carries them as the input does.
    for (std::size_t i = 0; i < options.input_attributes.size() && i < approx.attributes.size(); ++i) {
      const VertexAttribute &in = options.input_attributes[i], &out = approx.attributes[i];
      const double w = attribute_weight(in.kind, options.attribute_weights);
      if (w > 0 && in.components == out.components && !options.point_source.empty()) {
        channels_.push_back({&in.values, &out.values, in.components, value_width_, w * w});
        value_width_ += in.components;
      }
    }
    faces_at_.assign(n, {});
    for (std::uint32_t f = 0; f < face_count(); ++f)
      for (int k = 0; k < 3; ++k) faces_at_[tri_[3 * f + k]].push_back(f);
    scan_faces();
    assign_points();
    largest_ = 0;
    for (std::uint32_t f = 0; f < face_count(); ++f) largest_ = std::max(largest_, local(f));
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
    if (opt_.relocations > 0 && mesh_.vertex_properties.empty()) r.relocations = relocate();
    if (std::find(dead_face_.begin(), dead_face_.end(), 1) != dead_face_.end()) {
      std::size_t next = 0;
      std::vector<std::uint32_t>& materials = mesh_.face_materials;
      for (std::size_t f = 0; f < face_count(); ++f)
        if (!dead_face_[f]) {
          if (!materials.empty()) materials[next] = materials[f];
          std::copy_n(&tri_[3 * f], 3, &tri_[3 * next++]);
        }
      tri_.resize(3 * next);
      if (!materials.empty()) materials.resize(next);
    }
    mesh_.indices = tri_;
    mesh_.positions.resize(3 * x_.size());
    for (std::uint32_t v : moved_) {
      const Vec3 p = frame_.to_model(x_[v]);
      mesh_.positions[3 * std::size_t(v)] = p.x, mesh_.positions[3 * std::size_t(v) + 1] = p.y,
                                 mesh_.positions[3 * std::size_t(v) + 2] = p.z;
    }
    return r;
  }

 private:
  using Corners = std::array<std::uint32_t, 3>;
  std::uint32_t face_count() const { return std::uint32_t(tri_.size() / 3); }
  Vec3 point(std::uint32_t p) const { return {points_[3 * p], points_[3 * p + 1], points_[3 * p + 2]}; }
  std::array<std::uint32_t, 3> face(std::uint32_t f) const { return {tri_[3 * f], tri_[3 * f + 1], tri_[3 * f + 2]}; }

  // Point p's error of appearance against face (a, b, c): the weighted squared difference between
  // its input vertex's values and the face's interpolated at p's closest point, times p's share of
  // the area (in the units of the points' squared distances). 0 without attributes.
  double value_error(std::uint32_t p, const std::array<std::uint32_t, 3>& t) const {
    if (channels_.empty()) return 0;
    const std::array<double, 3> w = measure_detail::closest_point_weights(point(p), x_[t[0]], x_[t[1]], x_[t[2]]);
    const std::size_t s = opt_.point_source[p];
    return weights_[p] * weight_scale_ *
           values_gap(t, w, [&](const Channel& ch, std::uint32_t k) { return (*ch.input)[s * ch.components + k]; });
  }
  // The weighted squared gap between the output's values on face t, interpolated by w, and
  // `target(channel, component)`, the channels weighted as in the metric.
  template <class Target>
  double values_gap(const std::array<std::uint32_t, 3>& t, const std::array<double, 3>& w, Target target) const {
    double error = 0;
    for (const Channel& ch : channels_) {
      const std::vector<double>& out = *ch.output;
      const std::size_t n = ch.components;
      double sum = 0;
      for (std::uint32_t k = 0; k < n; ++k) {
        const double d = w[0] * out[t[0] * n + k] + w[1] * out[t[1] * n + k] + w[2] * out[t[2] * n + k] - target(ch, k);
        sum += d * d;
      }
      error += ch.weight2 * sum;
    }
    return error;
  }

  // The input's surface between its vertices, round a change: each input triangle within `radius`
  // of `centre` gives its centroid and edge midpoints (a quarter of its area each, in the frame's
  // units, as the points' weights) with the input's values there. The input's vertices alone miss
  // what lies between them: a move that slides the values along a face of a coarse output.
  struct ValueSamples {
    std::vector<Vec3> at;
    std::vector<double> weight, values;  // values: the channels' components per sample
    std::vector<std::uint32_t> context;  // the faces round the change that it leaves as they are
    // Per sample, its nearest context face's squared distance (HUGE_VAL without one) and the
    // sample's error on that face: the same before and after the change, so found once.
    std::vector<double> context_d2, context_error;
  };
  // The samples round a change of faces `changed` (their slots, as they are before it).
  void sample_values(std::span<const std::uint32_t> changed, const Vec3* also, ValueSamples& s) {
    s.at.clear(), s.weight.clear(), s.values.clear(), s.context.clear();
    if (channels_.empty() || opt_.input_faces.empty()) return;
    std::vector<std::uint32_t> corners;
    for (std::uint32_t f : changed) corners.insert(corners.end(), &tri_[3 * f], &tri_[3 * f] + 3);
    auto [centre, radius] = ball_of(corners);
    if (also) radius = std::max(radius, length(*also - centre));
    for (std::uint32_t v : corners)
      for (std::uint32_t g : faces_at_[v])
        if (std::find(changed.begin(), changed.end(), g) == changed.end()) s.context.push_back(g);
    std::sort(s.context.begin(), s.context.end());
    s.context.erase(std::unique(s.context.begin(), s.context.end()), s.context.end());
    std::vector<std::uint32_t> near;
    surface_.triangles_near(centre, radius, near);
    std::sort(near.begin(), near.end());  // the sums in one order, whatever the tree's walk
    constexpr double kAt[4][3] = {{1.0 / 3, 1.0 / 3, 1.0 / 3}, {0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5}};
    for (std::uint32_t t : near) {
      const std::array<double, 9> c = surface_.triangle(t);
      const Vec3 corner[3] = {{c[0], c[1], c[2]}, {c[3], c[4], c[5]}, {c[6], c[7], c[8]}};
      const double area = 0.5 * length(cross(corner[1] - corner[0], corner[2] - corner[0]));
      const std::uint32_t* v = &opt_.input_faces[3 * std::size_t(t)];
      for (const auto& w : kAt) {
        const Vec3 q = corner[0] * w[0] + corner[1] * w[1] + corner[2] * w[2];
        if (measure_detail::squared_distance(q, centre) > radius * radius) continue;
        s.at.push_back(q), s.weight.push_back(0.25 * area);
        for (const Channel& ch : channels_)
          for (std::uint32_t k = 0; k < ch.components; ++k) {
            double x = 0;
            for (int i = 0; i < 3; ++i) x += w[i] * (*ch.input)[std::size_t(v[i]) * ch.components + k];
            s.values.push_back(x);
          }
      }
    }
    // Each sample's nearest context face, the first of the nearest in s.context's order. Faces
    // whose box is farther than the nearest found so far are passed over, the box nearest first.
    ContextBoxes& boxes = scratch_boxes_;
    const std::size_t n = s.context.size();
    for (auto* bound : {&boxes.lo[0], &boxes.lo[1], &boxes.lo[2], &boxes.hi[0], &boxes.hi[1], &boxes.hi[2]})
      bound->resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const Corners t = face(s.context[k]);
      for (int a = 0; a < 3; ++a) {
        const double c0 = x_[t[0]][a], c1 = x_[t[1]][a], c2 = x_[t[2]][a];
        boxes.lo[a][k] = std::min({c0, c1, c2}) - kWiden, boxes.hi[a][k] = std::max({c0, c1, c2}) + kWiden;
      }
    }
    std::vector<double>& gaps = scratch_gaps_;
    gaps.resize(n);
    s.context_d2.assign(s.at.size(), HUGE_VAL), s.context_error.assign(s.at.size(), 0);
    for (std::size_t i = 0; i < s.at.size() && n > 0; ++i) {
      const Vec3 p = s.at[i];
      for (std::size_t k = 0; k < n; ++k) {
        const double dx = std::max(std::max(boxes.lo[0][k] - p.x, p.x - boxes.hi[0][k]), 0.0);
        const double dy = std::max(std::max(boxes.lo[1][k] - p.y, p.y - boxes.hi[1][k]), 0.0);
        const double dz = std::max(std::max(boxes.lo[2][k] - p.z, p.z - boxes.hi[2][k]), 0.0);
        gaps[k] = dx * dx + dy * dy + dz * dz;
      }
      const std::size_t first = std::size_t(std::min_element(gaps.begin(), gaps.end()) - gaps.begin());
      double& best_d2 = s.context_d2[i];
      std::size_t best = n;
      const auto consider = [&](std::size_t k) {
        const double d2 = triangle_d2(p, face(s.context[k]));
        if (d2 < best_d2 || (d2 == best_d2 && k < best)) best_d2 = d2, best = k;
      };
      consider(first);
      for (std::size_t k = 0; k < n; ++k)
        if (k != first && !beyond(gaps[k], best_d2)) consider(k);
      if (best < n) s.context_error[i] = sample_error(s, i, face(s.context[best]));
    }
  }
  // Boxes are widened by far more than the rounding of a closest point on a triangle inside them
  // (frame units: the points lie within the unit box), so that a box `beyond` a squared distance
  // holds no point as near.
  static constexpr double kWiden = 1e-9;
  struct ContextBoxes {
    std::vector<double> lo[3], hi[3];  // per axis, so that a sample's gaps to them run in vectors
  };
  static bool beyond(double gap2, double d2) { return gap2 > d2 * (1 + 1e-9); }
  double triangle_d2(const Vec3& p, const Corners& t) const {
    return measure_detail::squared_distance(
        p, measure_detail::closest_point_on_triangle(p, x_[t[0]], x_[t[1]], x_[t[2]]));
  }
  // Sample i's error on face t: its values against t's interpolated at its closest point on t.
  double sample_error(const ValueSamples& s, std::size_t i, const Corners& t) const {
    const std::array<double, 3> w =
        measure_detail::closest_point_weights(s.at[i], x_[t[0]], x_[t[1]], x_[t[2]]);
    const double* values = &s.values[i * value_width_];
    return s.weight[i] *
           values_gap(t, w, [&](const Channel& ch, std::uint32_t k) { return values[ch.first + k]; });
  }
  // The samples' error of appearance against the nearest of `count` faces (`corners(k)`: its three
  // vertices) and the faces round them (s.context: a sample nearer one of those is theirs, as in
  // the measure, which asks the whole output), their values interpolated at its closest point.
  // (A sample farther from the box of the `count` faces than from its nearest context face keeps
  // that face: the choice a test of every face would make, ties going to the `count` faces.)
  template <class CornersOf>
  double samples_value_error(const ValueSamples& s, std::size_t count, CornersOf corners) const {
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (std::size_t k = 0; k < count; ++k)
      for (std::uint32_t c : corners(k))
        for (int a = 0; a < 3; ++a)
          lo[a] = std::min(lo[a], x_[c][a] - kWiden), hi[a] = std::max(hi[a], x_[c][a] + kWiden);
    double total = 0;
    for (std::size_t i = 0; i < s.at.size(); ++i) {
      const Vec3& p = s.at[i];
      double gap2 = 0;
      for (int a = 0; a < 3; ++a) {
        const double gap = std::max({lo[a] - p[a], p[a] - hi[a], 0.0});
        gap2 += gap * gap;
      }
      if (beyond(gap2, s.context_d2[i])) {
        total += s.context_error[i];
        continue;
      }
      Corners best{};
      double best_d2 = HUGE_VAL;
      for (std::size_t k = 0; k < count; ++k) {
        const Corners t = corners(k);
        const double d2 = triangle_d2(p, t);
        if (d2 < best_d2) best_d2 = d2, best = t;
      }
      total += best_d2 <= s.context_d2[i] ? sample_error(s, i, best) : s.context_error[i];
    }
    return total;
  }
  // The error of appearance round a change, before or after it: points `pts`, point i on face
  // corners(on[i]), and samples s, each on the nearest of the `count` faces corners(k) and of
  // s.context.
  template <class CornersOf>
  double appearance_error(std::span<const std::uint32_t> pts, std::span<const std::uint32_t> on, const ValueSamples& s,
                          std::size_t count, CornersOf corners) const {
    double total = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) total += value_error(pts[i], corners(on[i]));
    return total + samples_value_error(s, count, corners);
  }
  // The ball round a set of vertices (their mean, and the largest distance to it).
  std::pair<Vec3, double> ball_of(std::span<const std::uint32_t> vertices) const {
    Vec3 centre{0, 0, 0};
    for (std::uint32_t v : vertices) centre = centre + x_[v];
    centre = centre * (1.0 / double(vertices.size()));
    double radius = 0;
    for (std::uint32_t v : vertices) radius = std::max(radius, length(x_[v] - centre));
    return {centre, radius};
  }

  // The samples of face abc, searched from input face `hint`; stops at the first sample at least
  // `limit` from the input (then `energy` is incomplete and `most` at least limit).
  FaceScore score(const Vec3& a, const Vec3& b, const Vec3& c, std::uint32_t hint,
                  double limit = HUGE_VAL) const {
    FaceScore s;
    for (const SampleAt& at : kOrder) {
      const double d = surface_.distance(a + (b - a) * at.u + (c - a) * at.v, &hint);
      if (d > s.most) s.most = d, s.u = at.u, s.v = at.v;
      s.energy += d * d;
      if (d >= limit) break;
    }
    s.energy *= 0.5 * length(cross(b - a, c - a)) / kSamples;
    s.hint = hint;
    return s;
  }
  // Moves s's largest sample of face abc to the peak of the distance near it (a grid's points miss
  // the peak between them): a climb over the face in halving steps.
  void climb(const Vec3& a, const Vec3& b, const Vec3& c, FaceScore& s) const {
    constexpr int kSteps = 4;
    constexpr double kMoves[6][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, -1}, {-1, 1}};
    double &u = s.u, &v = s.v, &most = s.most, h = 1.0 / kGrid;
    std::uint32_t hint = s.hint;
    for (int step = 0; step < kSteps; ++step) {
      h *= 0.5;
      const double u0 = u, v0 = v;
      for (const auto& m : kMoves) {
        const double x = u0 + m[0] * h, y = v0 + m[1] * h;
        if (x < 0 || y < 0 || x + y > 1) continue;
        const double d = surface_.distance(a + (b - a) * x + (c - a) * y, &hint);
        if (d > most) most = d, u = x, v = y;
      }
    }
  }
  FaceScore score(std::uint32_t f, double limit = HUGE_VAL) const {
    const std::uint32_t* t = &tri_[3 * f];
    return score(x_[t[0]], x_[t[1]], x_[t[2]], hint_[f], limit);
  }
  void ensure_scored(std::uint32_t f) {
    if (scored_[f]) return;
    score_[f] = score(f);
    scored_[f] = 1;
    rescored_.push_back(f);
  }

  // Where the far faces are, for a fraction of the samples' searches: per face, the largest
  // distance of its centroid and edge midpoints (the middle of an edge across a groove is where
  // it is farthest from it) to the input (near_), and the largest of those and of the input
  // points' distances (largest_). The exact samples of a face are taken when a flip needs them.
  // An interior edge's midpoint is searched for once, by the lower of its two faces (across(): its
  // coordinates are the same from both ends), and read by the other: on a closed mesh 2.5
  // searches a face instead of 4, for the same distances.
  void scan_faces() {
    const std::size_t nf = face_count();
    near_.assign(nf, 0);
    hint_.assign(nf, UINT32_MAX);
    scored_.assign(nf, 0);
    score_.assign(nf, {});
    std::vector<std::uint32_t> owner(3 * nf);  // per face edge (3 f + k: t[k] to t[k + 1]): the slot that searches
    std::vector<double> middle(3 * nf);        // per searching slot: its midpoint's distance
    for_chunks(nf, kChunk, resolve_threads(opt_.threads), [&](std::size_t, std::size_t begin, std::size_t end) {
      std::uint32_t hint = UINT32_MAX;
      for (std::size_t f = begin; f < end; ++f) {
        const std::uint32_t* t = &tri_[3 * f];
        const Vec3 &a = x_[t[0]], &b = x_[t[1]], &c = x_[t[2]];
        near_[f] = surface_.distance((1.0 / 3) * (a + b + c), &hint);
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t u = t[k], w = t[(k + 1) % 3], g = across(std::uint32_t(f), u, w);
          std::uint32_t slot = std::uint32_t(3 * f + k);
          if (g < f)  // the edge runs from w to u in g
            for (int j = 0; j < 3; ++j)
              if (tri_[3 * g + j] == w && tri_[3 * g + (j + 1) % 3] == u) slot = std::uint32_t(3 * g + j);
          owner[3 * f + k] = slot;
          if (slot == 3 * f + k) middle[slot] = surface_.distance(0.5 * (x_[u] + x_[w]), &hint);
        }
        hint_[f] = hint;
      }
    });
    for (std::size_t f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) near_[f] = std::max(near_[f], middle[owner[3 * f + k]]);
  }

  // Each input point goes to its closest output face (of two as close, the lower index): only the
  // points of a flip's two faces can come farther from the output by it. A point a local search
  // already placed (FarRepairOptions::point_faces) within half the output's largest distance to the
  // input (after scan_faces) keeps that face: the far faces are chosen from 3/4 of the largest, so
  // such a point decides none of them whichever near face it goes to, and the tree's search, most of
  // the set-up's work, is left to the points that could.
  void assign_points() {
    const std::size_t count = weights_.size();
    const bool given = opt_.point_faces.size() == count;
    const double keep = 0.5 * *std::max_element(near_.begin(), near_.end());
    std::vector<std::uint32_t> face_of(count, UINT32_MAX);
    d2_.assign(count, HUGE_VAL);
    std::atomic<bool> need_tree = !given;
    if (given)
      for_chunks(count, kChunk, resolve_threads(opt_.threads),
                 [&](std::size_t, std::size_t begin, std::size_t end) {
                   bool missed = false;
                   for (std::size_t p = begin; p < end; ++p) {
                     const std::uint32_t f = opt_.point_faces[p];
                     if (f >= face_count()) {
                       missed = true;
                       continue;
                     }
                     const auto [a, b, c] = face(f);
                     const Vec3 q = point(std::uint32_t(p));
                     const double d2 = measure_detail::squared_distance(
                         q, measure_detail::closest_point_on_triangle(q, x_[a], x_[b], x_[c]));
                     if (d2 < keep * keep)
                       face_of[p] = f, d2_[p] = d2;
                     else
                       missed = true;
                   }
                   if (missed) need_tree = true;
                 });
    if (need_tree) {
      std::vector<double> corners(9 * std::size_t(face_count()));
      for (std::size_t f = 0; f < face_count(); ++f)
        for (int k = 0; k < 3; ++k) {
          const Vec3& p = x_[tri_[3 * f + k]];
          corners[9 * f + 3 * k] = p.x, corners[9 * f + 3 * k + 1] = p.y, corners[9 * f + 3 * k + 2] = p.z;
        }
      const measure_detail::TriangleBvh tree(corners, resolve_threads(opt_.threads));
      for_chunks(count, kChunk, resolve_threads(opt_.threads),
                 [&](std::size_t, std::size_t begin, std::size_t end) {
                   std::uint32_t hint = UINT32_MAX;
                   for (std::size_t p = begin; p < end; ++p) {
                     if (face_of[p] != UINT32_MAX) continue;
                     const auto hit = tree.closest(&points_[3 * p], &hint);
                     face_of[p] = hit.triangle, d2_[p] = hit.d2;
                   }
                 });
    }
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
  // Whether a relocation may split at a border: the input's border points are given or found.
  bool border_allowed() const { return !opt_.point_on_border.empty() || opt_.find_border_points; }
  // The input's border points (FarRepairOptions::point_on_border, or found at the first call).
  std::span<const std::uint8_t> border_points() {
    if (!opt_.point_on_border.empty()) return opt_.point_on_border;
    if (found_border_.empty())
      found_border_ = points_on_border(opt_.input_faces, opt_.point_source, resolve_threads(opt_.threads));
    return found_border_;
  }
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

  // Each input point of `pts` to the nearest of `count` faces (face k's corners by corners(k); of
  // two as near, the lower k): k in nearest[i], the squared distance in d2[i]. Returns the largest
  // squared distance.
  //
  // A change (flip, move, split or collapse) is refused when a point or a sample of its new faces
  // comes too far; both are tested, in either order with the same answer. The points need no
  // search of the input, a face's samples one each, so where a face has few points (fine outputs)
  // the points go first and refuse many changes before any search; where it has many (coarse
  // outputs) the samples go first, since the first sample of a refused change is usually too far.
  static bool points_first(std::size_t points, std::size_t faces) {
    return points <= kPointsFirstPerFace * faces;
  }
  static constexpr std::size_t kPointsFirstPerFace = 16;
  template <class CornersOf>
  double to_nearest_faces(std::span<const std::uint32_t> pts, std::size_t count, CornersOf corners,
                          std::vector<std::uint32_t>& nearest, std::vector<double>& d2) const {
    nearest.resize(pts.size());
    d2.resize(pts.size());
    double most2 = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Vec3 p = point(pts[i]);
      double best = HUGE_VAL;
      for (std::size_t k = 0; k < count; ++k) {
        const auto [a, b, c] = corners(k);
        const double d = measure_detail::squared_distance(p, measure_detail::closest_point_on_triangle(p, a, b, c));
        if (d < best) best = d, nearest[i] = std::uint32_t(k);
      }
      d2[i] = best;
      most2 = std::max(most2, best);
    }
    return most2;
  }
  // Adds the points' weighted squared distances to `energy`, in their order (after the faces'
  // samples: the sum of a change's share of E is made in one order).
  void add_points_energy(std::span<const std::uint32_t> pts, std::span<const double> d2,
                         double& energy) const {
    for (std::size_t i = 0; i < pts.size(); ++i) energy += weights_[pts[i]] * weight_scale_ * d2[i];
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
    std::vector<std::uint32_t>& pts = scratch_points_;
    pts.assign(points_of_[f1].begin(), points_of_[f1].end());
    pts.insert(pts.end(), points_of_[f2].begin(), points_of_[f2].end());
    const auto corners = [&](std::size_t k) {
      const Vec3* g = k == 0 ? g1 : g2;
      return std::array<Vec3, 3>{g[0], g[1], g[2]};
    };
    const bool early = points_first(pts.size(), 2);
    const auto points_near = [&] {
      return std::sqrt(to_nearest_faces(pts, 2, corners, scratch_nearest_, scratch_d2_)) < old_most;
    };
    if (early && !points_near()) return UINT32_MAX;
    const FaceScore s1 = score(g1[0], g1[1], g1[2], score_[f1].hint, old_most);
    if (s1.most >= old_most) return UINT32_MAX;
    const FaceScore s2 = score(g2[0], g2[1], g2[2], score_[f2].hint, old_most);
    if (s2.most >= old_most) return UINT32_MAX;
    if (!early && !points_near()) return UINT32_MAX;
    double old_energy = score_[f1].energy + score_[f2].energy;
    for (std::uint32_t f : {f1, f2})
      for (std::uint32_t p : points_of_[f]) old_energy += weights_[p] * weight_scale_ * d2_[p];
    double energy = s1.energy + s2.energy;
    add_points_energy(pts, scratch_d2_, energy);
    if (energy > old_energy * (1 + opt_.error_margin)) return UINT32_MAX;
    if (!channels_.empty()) {
      // The values at the points and between them, on the faces as they are and as they would be.
      const std::uint32_t changed[2] = {f1, f2};
      sample_values(changed, nullptr, scratch_samples_);
      std::vector<std::uint32_t>& on = scratch_on_;
      on.assign(pts.size(), 1);
      std::fill_n(on.begin(), points_of_[f1].size(), 0);
      const double before = appearance_error(pts, on, scratch_samples_, 2, [&](std::size_t k) { return face(k == 0 ? f1 : f2); });
      const double after = appearance_error(pts, scratch_nearest_, scratch_samples_, 2, [&](std::size_t k) {
        return k == 0 ? Corners{a, d, c} : Corners{b, c, d};
      });
      if (after > before) return UINT32_MAX;
    }

    // Made: f1 becomes (a,d,c), f2 (b,c,d); b leaves f1 and d joins it, a leaves f2 and c joins it.
    tri_[3 * f1] = a, tri_[3 * f1 + 1] = d, tri_[3 * f1 + 2] = c;
    tri_[3 * f2] = b, tri_[3 * f2 + 1] = c, tri_[3 * f2 + 2] = d;
    std::erase(faces_at_[b], f1), faces_at_[d].push_back(f1);
    std::erase(faces_at_[a], f2), faces_at_[c].push_back(f2);
    score_[f1] = s1, score_[f2] = s2;
    scored_[f1] = scored_[f2] = 1;
    points_of_[f1].clear(), points_of_[f2].clear();
    for (std::size_t i = 0; i < pts.size(); ++i)
      d2_[pts[i]] = scratch_d2_[i], points_of_[scratch_nearest_[i] == 0 ? f1 : f2].push_back(pts[i]);
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
    for (std::uint32_t f : fan) {
      const std::uint32_t* t = &tri_[3 * f];
      const Vec3 n = normalized(normal(t[0], t[1], t[2]));
      x_[v] = y;
      const Vec3 m = normalized(normal(t[0], t[1], t[2]));
      x_[v] = x;
      if (dot(m, m) == 0 || dot(n, m) < cos_turn_) return false;
    }
    // The fan's points, each to the nearest of the fan's faces after the move.
    std::vector<std::uint32_t>& pts = scratch_points_;
    std::vector<std::uint32_t>& on = scratch_on_;  // each point's face (its index in the fan)
    pts.clear(), on.clear();
    for (std::size_t k = 0; k < fan.size(); ++k) {
      pts.insert(pts.end(), points_of_[fan[k]].begin(), points_of_[fan[k]].end());
      on.resize(pts.size(), std::uint32_t(k));
    }
    const auto corners = [&](std::size_t k) {
      const std::uint32_t* t = &tri_[3 * fan[k]];
      return std::array<Vec3, 3>{x_[t[0]], x_[t[1]], x_[t[2]]};
    };
    const bool early = points_first(pts.size(), fan.size());
    const auto points_near = [&] {
      x_[v] = y;
      const double most2 = to_nearest_faces(pts, fan.size(), corners, scratch_nearest_, scratch_d2_);
      x_[v] = x;
      return std::sqrt(most2) < old_most;
    };
    if (early && !points_near()) return false;
    std::vector<FaceScore> scores(fan.size());
    for (std::size_t i = 0; i < fan.size(); ++i) {
      const std::uint32_t* t = &tri_[3 * fan[i]];
      x_[v] = y;
      scores[i] = score(x_[t[0]], x_[t[1]], x_[t[2]], score_[fan[i]].hint, old_most);
      x_[v] = x;
      if (scores[i].most >= old_most) return false;
    }
    if (!early && !points_near()) return false;
    double energy = 0;
    for (std::size_t i = 0; i < fan.size(); ++i) energy += scores[i].energy;
    add_points_energy(pts, scratch_d2_, energy);
    if (energy > old_energy * (1 + opt_.error_margin)) return false;
    if (!channels_.empty()) {
      // The values at the points and between them, round the fan where it is and where it goes.
      const auto fan_face = [&](std::size_t k) { return face(fan[k]); };
      sample_values(fan, &y, scratch_samples_);
      const double before = appearance_error(pts, on, scratch_samples_, fan.size(), fan_face);
      x_[v] = y;
      const double after = appearance_error(pts, scratch_nearest_, scratch_samples_, fan.size(), fan_face);
      x_[v] = x;
      if (after > before) return false;
    }
    x_[v] = y;
    for (std::size_t i = 0; i < fan.size(); ++i) score_[fan[i]] = scores[i], scored_[fan[i]] = 1, points_of_[fan[i]].clear();
    for (std::size_t i = 0; i < pts.size(); ++i)
      d2_[pts[i]] = scratch_d2_[i], points_of_[fan[scratch_nearest_[i]]].push_back(pts[i]);
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

  // ---- Relocations: a vertex taken from the flattest place to the farthest ----

  static constexpr std::uint32_t kNew = UINT32_MAX - 1;  // the new vertex, in a planned face
  static constexpr std::uint32_t kNewTwin = UINT32_MAX - 2;  // its twin, on a crack's other side
  static constexpr double kNothingFar = 1e-9;
  // At most one face in this many may be given up by border splits paired with interior collapses.
  static constexpr std::size_t kGiveUpShare = 256;
  static constexpr std::size_t kStuck = 8;
  static constexpr double kScoreFrom = 0.4;
  static constexpr double kBorderReach = 4;

  // A planned set of new faces replacing `old` faces: their scores, and the old faces' input points
  // each with its nearest new face.
  struct Plan {
    std::vector<std::uint32_t> old;    // the faces replaced (their slots are reused first)
    std::vector<Corners> faces;        // the new faces (kNew: the new vertex)
    std::vector<std::uint32_t> parent;  // per new face, the old face it comes from
    std::vector<FaceScore> scores;
    std::vector<std::uint32_t> points, nearest;  // the old faces' points; index into faces
    std::vector<double> d2;
    double most = 0;          // the new faces' largest distance, both ways
    double old_energy = 0, energy = 0;
  };
  struct Split : Plan {
    Vec3 y{};                        // where the new vertex goes
    std::uint32_t point = UINT32_MAX;  // the input point at or nearest y
    bool border = false;             // a border edge's: one face more, not two
    bool at_point = false;           // y is the point's place
    bool crack = false;              // a border edge and its twin: two new vertices, two faces more
    bool hold_new = false;           // the new vertex is held (it splits a held edge)
    // The new vertex's attribute values: interpolated from these corners with these shares (the
    // edge's ends, or the face's corners, at the new vertex's place on the divided edge or face),
    // so that the split leaves the values along the old faces as they were; its twin's from the
    // twin edge's ends.
    std::array<std::uint32_t, 3> from{}, twin_from{};
    std::array<double, 3> share{}, share_twin{};
  };
  struct Collapse : Plan {
    std::uint32_t u = 0, v = 0;  // u goes into v
  };

  // The faces that have edge ab (either way round).
  int edge_faces(std::uint32_t a, std::uint32_t b) const {
    int n = 0;
    for (std::uint32_t g : faces_at_[a]) {
      const std::uint32_t* t = &tri_[3 * g];
      n += t[0] == b || t[1] == b || t[2] == b;
    }
    return n;
  }
  bool border_edge(std::uint32_t a, std::uint32_t b) const { return edge_faces(a, b) == 1; }
  // Whether a face with the same three corners as one of `faces` is already there.
  bool any_face_exists(const std::vector<Corners>& faces) const {
    for (const Corners& t : faces) {
      const auto same = [&](std::uint32_t g) {
        const std::uint32_t* o = &tri_[3 * g];
        return std::is_permutation(o, o + 3, t.begin());
      };
      if (std::any_of(faces_at_[t[0]].begin(), faces_at_[t[0]].end(), same)) return true;
    }
    return false;
  }
  // The other vertices at v's position.
  std::span<const std::uint32_t> alike(std::uint32_t v) const {
    if (v >= alike_.size() || alike_[v] == UINT32_MAX) return {};
    return places_[alike_[v]];
  }
  // Whether another vertex at a's position has an edge to another at b's.
  bool joined_elsewhere(std::uint32_t a, std::uint32_t b) const {
    for (std::uint32_t x : alike(a))
      for (std::uint32_t y : alike(b))
        if (x != a && y != b && edge_faces(x, y) > 0) return true;
    return false;
  }
  // The border neighbours of v (the other ends of its border edges).
  std::vector<std::uint32_t> border_neighbours(std::uint32_t v) const {
    std::vector<std::uint32_t> r;
    for (std::uint32_t x : ring(v))
      if (border_edge(v, x)) r.push_back(x);
    return r;
  }

  Vec3 at(std::uint32_t v, const Vec3& y) const { return v == kNew || v == kNewTwin ? y : x_[v]; }

  // Scores plan p's faces (the new vertex at y), stopping at the first whose samples reach
  // `limit`, and hands its old faces' points to the nearest new face. False: a face reached the
  // limit (p.most is then not final).
  bool score_plan(Plan& p, const Vec3& y, double limit) const {
    p.scores.resize(p.faces.size());
    p.most = 0, p.energy = 0, p.old_energy = 0;
    p.points.clear();
    for (std::uint32_t f : p.old) {
      p.old_energy += score_[f].energy;
      for (std::uint32_t q : points_of_[f]) p.points.push_back(q), p.old_energy += weights_[q] * weight_scale_ * d2_[q];
    }
    const auto corners = [&](std::size_t k) {
      const Corners& t = p.faces[k];
      return std::array<Vec3, 3>{at(t[0], y), at(t[1], y), at(t[2], y)};
    };
    const bool early = points_first(p.points.size(), p.faces.size());
    double most2 = 0;
    const auto points_near = [&] {
      most2 = to_nearest_faces(p.points, p.faces.size(), corners, p.nearest, p.d2);
      return std::sqrt(most2) < limit;
    };
    if (early && !points_near()) return false;
    for (std::size_t i = 0; i < p.faces.size(); ++i) {
      const Corners& t = p.faces[i];
      p.scores[i] = score(at(t[0], y), at(t[1], y), at(t[2], y), score_[p.parent[i]].hint, limit);
      if (p.scores[i].most >= limit) return false;
      climb(at(t[0], y), at(t[1], y), at(t[2], y), p.scores[i]);
      if (p.scores[i].most >= limit) return false;
      p.most = std::max(p.most, p.scores[i].most);
      p.energy += p.scores[i].energy;
    }
    if (!early && !points_near()) return false;
    add_points_energy(p.points, p.d2, p.energy);
    p.most = std::max(p.most, std::sqrt(most2));
    return p.most < limit;
  }

  // Whether each new face of p is not degenerate and turns by at most the limit from its parent,
  // as its parent's line was before the relocations (first_normal_): measured from the parent as
  // it is, splits beside an earlier split's steep faces would add turn to turn, and fold.
  bool keeps_facing(const Plan& p, const Vec3& y) const {
    for (std::size_t i = 0; i < p.faces.size(); ++i) {
      const Corners& t = p.faces[i];
      const Vec3 p0 = at(t[0], y), p1 = at(t[1], y), p2 = at(t[2], y);
      const Vec3 e = cross(p1 - p0, p2 - p0);
      // Degenerate to rounding (a corner on the line of the other two): its normal means nothing.
      const double longest2 = std::max({dot(p1 - p0, p1 - p0), dot(p2 - p1, p2 - p1), dot(p0 - p2, p0 - p2)});
      if (!(dot(e, e) > 1e-18 * longest2 * longest2)) return false;
      const Vec3 m = normalized(e);
      const Vec3& n = first_normal_[p.parent[i]];
      if (dot(n, n) == 0 || dot(m, n) < cos_turn_) return false;
    }
    return true;
  }

  // The input's surface between its vertices round plan p (the points are only its vertices, and
  // a large input triangle, such as a flat cap's, has none where the output may leave it): a sample
  // of an input triangle near p's new faces may not end `limit` or farther from them and from the
  // faces round the plan (a crack's other side included) when it was nearer than that to the old
  // faces. (Samples already that far, by this local view, are near other faces or far already.)
  bool input_stays_near(const Plan& p, const Vec3& y, double limit) {
    Vec3 centre{0, 0, 0};
    for (const Corners& t : p.faces)
      for (std::uint32_t v : t) centre = centre + at(v, y);
    centre = centre * (1.0 / double(3 * p.faces.size()));
    double radius = 0;
    for (const Corners& t : p.faces)
      for (std::uint32_t v : t) radius = std::max(radius, length(at(v, y) - centre));
    std::vector<std::uint32_t>& context = scratch_context_;
    context.clear();
    for (const Corners& t : p.faces)
      for (std::uint32_t v : t)
        if (v < kNewTwin) {
          const auto add = [&](std::uint32_t u) {
            for (std::uint32_t g : faces_at_[u])
              if (std::find(p.old.begin(), p.old.end(), g) == p.old.end()) context.push_back(g);
          };
          add(v);
          for (std::uint32_t u : alike(v)) add(u);  // a crack's other side too
        }
    std::sort(context.begin(), context.end());
    context.erase(std::unique(context.begin(), context.end()), context.end());
    // Each sample asks only whether a face of a set lies within the limit, so the first face
    // within ends the search, and a face whose box (widened far beyond the rounding of the
    // closest-point computation) is farther is skipped: the same answers as the nearest distance.
    std::vector<BoxedTriangle>& planned = scratch_planned_;
    std::vector<BoxedTriangle>& rest = scratch_rest_;
    std::vector<BoxedTriangle>& old = scratch_old_;
    planned.clear(), rest.clear(), old.clear();
    for (const Corners& t : p.faces)
      planned.push_back(BoxedTriangle::of(at(t[0], y), at(t[1], y), at(t[2], y)));
    const auto current = [&](std::uint32_t f) {
      return BoxedTriangle::of(x_[tri_[3 * f]], x_[tri_[3 * f + 1]], x_[tri_[3 * f + 2]]);
    };
    for (std::uint32_t f : context) rest.push_back(current(f));
    for (std::uint32_t f : p.old) old.push_back(current(f));
    std::vector<std::uint32_t>& near = scratch_near_;
    near.clear();
    surface_.triangles_near(centre, radius, near);
    const double limit2 = limit * limit, radius2 = radius * radius;
    const auto any_within = [limit2](const Vec3& q, const std::vector<BoxedTriangle>& faces) {
      for (const BoxedTriangle& t : faces)
        if (t.box_distance2(q) < limit2 &&
            measure_detail::squared_distance(q, measure_detail::closest_point_on_triangle(q, t.a, t.b, t.c)) <
                limit2)
          return true;
      return false;
    };
    for (std::uint32_t t : near) {
      const std::array<double, 9> c = surface_.triangle(t);
      const Vec3 a{c[0], c[1], c[2]}, b{c[3], c[4], c[5]}, d{c[6], c[7], c[8]};
      // Samples no farther apart than a quarter of the region, up to 16 divisions an edge.
      const double longest = std::max({length(b - a), length(d - b), length(a - d)});
      const int m = std::clamp(int(std::ceil(4 * longest / std::max(radius, 1e-300))), 1, 16);
      for (int i = 0; i <= m; ++i)
        for (int j = 0; i + j <= m; ++j) {
          const Vec3 q = a + (b - a) * (double(i) / m) + (d - a) * (double(j) / m);
          if (measure_detail::squared_distance(q, centre) > radius2) continue;
          // Near the new faces, or near the faces round them: the input stays near.
          if (any_within(q, planned) || any_within(q, rest)) continue;
          if (any_within(q, old)) return false;
        }
    }
    return true;
  }

  // The split of far face f: at the point of f nearest the input's farthest from it (or of the
  // input's farthest point from f), the edge there divided when the point is near an interior
  // edge, else the face; the new vertex on the input. False: it would not lower the distance.
  bool plan_split(std::uint32_t f, Split& s) {
    const std::uint32_t* t = &tri_[3 * f];
    const Vec3 &a = x_[t[0]], &b = x_[t[1]], &c = x_[t[2]];
    Vec3 near{};
    if (near_most_[f] >= score_[f].most) {
      std::uint32_t far = UINT32_MAX;
      for (std::uint32_t q : points_of_[f])
        if (far == UINT32_MAX || d2_[q] > d2_[far]) far = q;
      if (far == UINT32_MAX) return false;
      s.point = far, s.y = point(far), s.at_point = true;
      near = measure_detail::closest_point_on_triangle(s.y, a, b, c);
    } else {
      std::uint32_t hint = score_[f].hint;
      near = a + (b - a) * score_[f].u + (c - a) * score_[f].v;
      s.y = surface_.closest_point(near, &hint), s.at_point = false;
      double best = HUGE_VAL;
      for (std::uint32_t q : points_of_[f]) {
        const double d2 = measure_detail::squared_distance(point(q), s.y);
        if (d2 < best) best = d2, s.point = q;
      }
    }
    const std::array<double, 3> w = measure_detail::closest_point_weights(near, a, b, c);
    const int k = int(std::min_element(w.begin(), w.end()) - w.begin());
    s.old = {f};
    s.faces.clear(), s.parent.clear();
    // Near an edge (the corner across it weighs little): the edge splits, so that no sliver is
    // left between the point and the edge.
    constexpr double kNearEdge = 0.2;
    const std::uint32_t ea = t[(k + 1) % 3], eb = t[(k + 2) % 3], ec = t[k];
    const std::uint32_t g = w[k] < kNearEdge ? across(f, ea, eb) : UINT32_MAX;
    std::uint32_t ed = UINT32_MAX;
    if (g != UINT32_MAX)
      for (int i = 0; i < 3; ++i)
        if (tri_[3 * g + i] != ea && tri_[3 * g + i] != eb) ed = tri_[3 * g + i];
    s.border = false, s.crack = false, s.hold_new = false;
    if (w[k] < kNearEdge && g == UINT32_MAX) {
      // A border edge: split along the input's border, at its input point farthest from the
      // output edge (or, when the output is what is far, nearest the far sample), so that the
      // border stays on the input's (a split that adds one face, paired with a border collapse).
      if (!border_allowed() || !border_edge(ea, eb)) return false;
      // Held ends stay as they are, unless only their place holds them (other vertices share it:
      // the sides of a crack the input never welded): where another side has the same edge, a
      // crack's two sides split together (a vertex more); where none has, the sides already part
      // there and this one splits alone.
      std::uint32_t f2 = UINT32_MAX;
      s.hold_new = held(ea) || held(eb);
      if (s.hold_new) {
        if (caller_held_[ea] || caller_held_[eb]) return false;
        if (joined_elsewhere(ea, eb)) {
          if (twin_[ea] == UINT32_MAX || twin_[eb] == UINT32_MAX) return false;
          if (!opt_.add_vertices || !border_edge(twin_[ea], twin_[eb])) return false;
          for (std::uint32_t h : faces_at_[twin_[ea]]) {
            const std::uint32_t* o = &tri_[3 * h];
            if (o[0] == twin_[eb] || o[1] == twin_[eb] || o[2] == twin_[eb]) f2 = h;
          }
          if (f2 == UINT32_MAX || f2 == f) return false;
        }
      }
      // The input's border points nearest the faces round the edge's ends (and their twins': the
      // points at a crack go to either side).
      std::vector<std::uint32_t>& around = scratch_context_;
      around.clear();
      for (std::uint32_t v : {ea, eb}) {
        around.insert(around.end(), faces_at_[v].begin(), faces_at_[v].end());
        for (std::uint32_t u : alike(v)) around.insert(around.end(), faces_at_[u].begin(), faces_at_[u].end());
      }
      std::sort(around.begin(), around.end());
      around.erase(std::unique(around.begin(), around.end()), around.end());
      // The split's faces at input point q, kept only where they turn no face over and q is not
      // at an end of the edge (such as the input vertex an end was kept at: nothing to split).
      using measure_detail::squared_distance;
      const double at_end2 = 1e-12 * squared_distance(x_[ea], x_[eb]);
      s.faces = {{ea, kNew, ec}, {kNew, eb, ec}};
      s.parent = {f, f};
      std::uint32_t best = UINT32_MAX;
      double key = 0;
      const auto consider = [&](std::uint32_t q, double d2) {
        if (best != UINT32_MAX && (d2 > key || (d2 == key && q > best))) return;
        const Vec3 y = point(q);
        if (squared_distance(y, x_[ea]) <= at_end2 || squared_distance(y, x_[eb]) <= at_end2) return;
        if (keeps_facing(s, y)) best = q, key = d2;
      };
      const std::span<const std::uint8_t> on_border = border_points();
      for (std::uint32_t h : around)
        for (std::uint32_t q : points_of_[h])
          if (on_border[q])
            consider(q, near_most_[f] >= score_[f].most ? -d2_[q] : squared_distance(point(q), near));
      // None there (a lone face standing for a small part, whose input points went to nearer faces
      // of other parts): the input border point nearest the far place, within kBorderReach times
      // its distance.
      if (best == UINT32_MAX) {
        if (border_by_x_.empty()) {
          for (std::uint32_t q = 0; q < on_border.size(); ++q)
            if (on_border[q]) border_by_x_.push_back({point(q).x, q});
          std::sort(border_by_x_.begin(), border_by_x_.end());
        }
        const double reach = kBorderReach * local(f);
        auto it = std::lower_bound(border_by_x_.begin(), border_by_x_.end(), std::pair{near.x - reach, 0u});
        for (; it != border_by_x_.end() && it->first <= near.x + reach; ++it) {
          const double d2 = squared_distance(point(it->second), near);
          if (d2 <= reach * reach) consider(it->second, d2);
        }
      }
      if (best == UINT32_MAX) return false;
      s.point = best, s.y = point(best), s.border = true, s.at_point = true, s.crack = false;
      if (f2 != UINT32_MAX) {
        // The other side's face, split the same way at the same place (the twin of the new vertex).
        const std::uint32_t* o = &tri_[3 * f2];
        int k2 = 0;
        while (o[k2] != twin_[ea]) ++k2;
        const bool along = o[(k2 + 1) % 3] == twin_[eb];
        const std::uint32_t other = o[(k2 + (along ? 2 : 1)) % 3];  // the corner off the edge
        // (a', b', c) -> (a', w', c), (w', b', c); (a', c, b') -> (a', c, w'), (w', c, b').
        const Corners first = along ? Corners{twin_[ea], kNewTwin, other} : Corners{twin_[ea], other, kNewTwin};
        const Corners second = along ? Corners{kNewTwin, twin_[eb], other} : Corners{kNewTwin, other, twin_[eb]};
        ensure_scored(f2);
        s.old.push_back(f2);
        s.faces = {s.faces[0], first, s.faces[1], second};
        s.parent = {f, f2, f, f2};
        s.border = false, s.crack = true;
      }
    } else if (g != UINT32_MAX && ed != UINT32_MAX && ed != ec) {
      ensure_scored(g);
      s.old.push_back(g);
      // The first of each parent's new faces takes its slot (apply).
      s.faces = {{ea, kNew, ec}, {eb, kNew, ed}, {kNew, eb, ec}, {kNew, ea, ed}};
      s.parent = {f, g, f, g};
    } else {
      s.faces = {{t[0], t[1], kNew}, {t[1], t[2], kNew}, {t[2], t[0], kNew}};
      s.parent = {f, f, f};
    }
    // The values at the new vertex's foot on the faces it divides (of an edge's two, the nearer),
    // and whether the plan mends the far place: its new faces nearer the input than it, and the
    // input near them.
    const auto mends = [&] {
      s.from = {t[0], t[1], t[2]};
      s.share = measure_detail::closest_point_weights(s.y, a, b, c);
      if (s.old.size() == 2 && !s.crack) {
        const std::uint32_t* o = &tri_[3 * g];
        const auto on = [&](const std::uint32_t* q, const std::array<double, 3>& w) {
          return x_[q[0]] * w[0] + x_[q[1]] * w[1] + x_[q[2]] * w[2];
        };
        const std::array<double, 3> w =
            measure_detail::closest_point_weights(s.y, x_[o[0]], x_[o[1]], x_[o[2]]);
        if (measure_detail::squared_distance(s.y, on(o, w)) <
            measure_detail::squared_distance(s.y, on(t, s.share)))
          s.from = {o[0], o[1], o[2]}, s.share = w;
      }
      if (s.crack) {  // the twin at the same place along the twin edge
        const Vec3 along = x_[eb] - x_[ea];
        const double u = std::clamp(dot(s.y - x_[ea], along) / std::max(dot(along, along), 1e-300), 0.0, 1.0);
        s.twin_from = {twin_[ea], twin_[eb], twin_[ea]};
        s.share_twin = {1 - u, u, 0};
      }
      return score_plan(s, s.y, HUGE_VAL) && s.most < local(f) && input_stays_near(s, s.y, local(f));
    };
    // A lone spike of the input (one vertex far above its neighbours, an outlier pixel of a
    // terrain): the faces up to its tip may turn by more than the limit, or, where the far place is
    // the input's point, pass farther from the input round it than the place they mend. Part of
    // the way up still cuts the largest distance (by the part), as far as the limit allows.
    const Vec3 base = near, tip = s.y;
    const bool faces_tip = keeps_facing(s, s.y);
    if (faces_tip && mends()) return true;
    if (s.border || s.crack || (faces_tip && !s.at_point)) return false;
    for (double part : {0.75, 0.5, 0.25}) {
      const Vec3 y = base + (tip - base) * part;
      if (!keeps_facing(s, y)) continue;
      s.y = y, s.at_point = false;
      if (mends()) return true;
    }
    return false;
  }

  // The vertices adjacent to v (ascending, once each).
  std::vector<std::uint32_t> ring(std::uint32_t v) const {
    std::vector<std::uint32_t> r;
    for (std::uint32_t f : faces_at_[v])
      for (int k = 0; k < 3; ++k)
        if (tri_[3 * f + k] != v) r.push_back(tri_[3 * f + k]);
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
    return r;
  }

  // What removing interior vertex v would add to E, roughly: its distance to the plane of its ring
  // (through the ring's centroid, normal to the fan), squared, times the fan's area.
  double removal_cost(std::uint32_t v) const {
    // (Round an interior vertex each neighbour is a corner of two of its faces: the mean of the
    // faces' other corners is the ring's centroid.)
    Vec3 centroid{0, 0, 0}, n{0, 0, 0};
    double area = 0;
    for (std::uint32_t f : faces_at_[v]) {
      const std::uint32_t* t = &tri_[3 * f];
      centroid = centroid + x_[t[0]] + x_[t[1]] + x_[t[2]] - x_[v];
      const Vec3 m = normal(t[0], t[1], t[2]);
      n = n + m;
      area += 0.5 * length(m);
    }
    centroid = centroid * (1.0 / double(2 * faces_at_[v].size()));
    const double d = dot(x_[v] - centroid, normalized(n));
    return d * d * area;
  }

  // The best collapse of u into a neighbour (lowest energy), its faces within `limit`; false: none.
  // `border`: u is a border vertex, and goes into one of its two border neighbours (the one face of
  // that edge dies); a corner (a turn above kCornerDegrees, as the contractions keep) stays.
  // Refusals are remembered until the mesh changes (forget_refused_collapses): the relocations ask
  // again for the same flattest vertices at each far place, mostly at lower limits.
  bool plan_collapse(std::uint32_t u, double limit, bool border, Collapse& best) {
    const std::uint64_t key = 2 * std::uint64_t(u) + (border ? 1 : 0);
    if (const auto it = refused_below_.find(key); it != refused_below_.end() && limit <= it->second)
      return false;
    // Whether every target was refused for a reason that holds at any lower limit too.
    bool refused_at_lower = true;
    const auto refuse = [&] {
      if (refused_at_lower) {
        double& at = refused_below_[key];
        at = std::max(at, limit);
      }
      return false;
    };
    const std::vector<std::uint32_t> around = ring(u);
    for (std::uint32_t x : around)
      if (held(x)) return refuse();
    std::vector<std::uint32_t> targets = around;
    if (border) {
      targets = border_neighbours(u);
      if (targets.size() != 2) return refuse();
      const Vec3 in = normalized(x_[u] - x_[targets[0]]), out = normalized(x_[targets[1]] - x_[u]);
      if (dot(in, out) < std::cos(kCornerDegrees * std::numbers::pi / 180)) return refuse();
    }
    const std::size_t dying = border ? 1 : 2;
    bool found = false, sampled = false;
    Collapse c;
    for (std::uint32_t v : targets) {
      // The faces of edge uv die; their third corners must be the only common neighbours of u and
      // v (the link condition: else the collapse pinches the surface).
      std::vector<std::uint32_t> opposite;
      c.old.clear(), c.faces.clear(), c.parent.clear();
      for (std::uint32_t f : faces_at_[u]) {
        const std::uint32_t* t = &tri_[3 * f];
        c.old.push_back(f);
        if (t[0] == v || t[1] == v || t[2] == v) {
          for (int k = 0; k < 3; ++k)
            if (t[k] != u && t[k] != v) opposite.push_back(t[k]);
          continue;
        }
        Corners moved{t[0], t[1], t[2]};
        for (std::uint32_t& k : moved)
          if (k == u) k = v;
        c.faces.push_back(moved), c.parent.push_back(f);
      }
      std::sort(opposite.begin(), opposite.end());
      if (opposite.size() != dying || std::adjacent_find(opposite.begin(), opposite.end()) != opposite.end()) continue;
      const std::vector<std::uint32_t> other = ring(v);
      std::vector<std::uint32_t> common;
      std::set_intersection(around.begin(), around.end(), other.begin(), other.end(), std::back_inserter(common));
      if (common != opposite) continue;
      // Nothing left of u's part (a lone triangle), or a face twice (a tetrahedron's): refused, so
      // that no part vanishes or folds onto itself.
      if (c.faces.empty() || any_face_exists(c.faces)) continue;
      if (!keeps_facing(c, {}) || !score_plan(c, {}, limit)) continue;
      // One that would not be chosen over the best so far is not tested further (the same choice).
      if (found && !(c.energy - c.old_energy < best.energy - best.old_energy)) continue;
      // (Not monotone in the limit: a lower one may pass where this one refuses.)
      if (!input_stays_near(c, {}, limit)) {
        refused_at_lower = false;
        continue;
      }
      // (u's faces, and so the samples round them, are the same whichever v it goes into.)
      if (!sampled) sample_values(c.old, nullptr, scratch_samples_), sampled = true;
      if (!keeps_appearance(c, scratch_samples_)) continue;
      if (!found || c.energy - c.old_energy < best.energy - best.old_energy) {
        best = c, best.u = u, best.v = v;
        found = true;
      }
    }
    return found || refuse();
  }
  // After a change to the mesh: no refusal holds any more.
  void forget_refused_collapses() { refused_below_.clear(); }

  // Whether collapse c (scored: its points and their new faces) leaves the error of appearance of
  // its points and of the samples s round it (sample_values of c.old) as it was, or lowers it (to
  // rounding: in a patch of one colour the values interpolate to the same, but for the last bits):
  // the vertex it takes away carries no values the others do not.
  bool keeps_appearance(const Plan& c, const ValueSamples& s) {
    if (channels_.empty()) return true;
    std::vector<std::uint32_t>& on = scratch_on_;  // each point's old face (c.points lists them face by face)
    on.clear();
    for (std::size_t k = 0; k < c.old.size(); ++k) on.resize(on.size() + points_of_[c.old[k]].size(), std::uint32_t(k));
    const double before = appearance_error(c.points, on, s, c.old.size(), [&](std::size_t k) { return face(c.old[k]); });
    const double after = appearance_error(c.points, c.nearest, s, c.faces.size(), [&](std::size_t k) { return c.faces[k]; });
    double weight = 0;
    for (std::uint32_t q : c.points) weight += weights_[q] * weight_scale_;
    for (double w : s.weight) weight += w;
    return after <= before + 1e-20 * weight;
  }

  // Vertex v's attribute values (appended when v is new): those of corners `from` by `share`;
  // normals renormalised, colours clamped, and what is never interpolated (skin joints and their
  // weights, tangents) taken from the corner of the largest share.
  void set_values(std::uint32_t v, const std::array<std::uint32_t, 3>& from, const std::array<double, 3>& share) {
    const int main = int(std::max_element(share.begin(), share.end()) - share.begin());
    for (VertexAttribute& a : mesh_.attributes) {
      const std::size_t n = a.components;
      if (a.values.size() < n * (std::size_t(v) + 1)) a.values.resize(n * (std::size_t(v) + 1));
      double* out = &a.values[n * v];
      const bool blend = a.kind == AttributeKind::Normal || a.kind == AttributeKind::TexCoord ||
                         a.kind == AttributeKind::Color || a.kind == AttributeKind::Scalar;
      for (std::size_t k = 0; k < n; ++k)
        out[k] = blend ? share[0] * a.values[n * from[0] + k] + share[1] * a.values[n * from[1] + k] +
                             share[2] * a.values[n * from[2] + k]
                       : a.values[n * from[main] + k];
      if (a.kind == AttributeKind::Normal) {
        double length2 = 0;
        for (std::size_t k = 0; k < n; ++k) length2 += out[k] * out[k];
        if (length2 > 0)
          for (std::size_t k = 0; k < n; ++k) out[k] /= std::sqrt(length2);
      }
      if (a.kind == AttributeKind::Color)
        for (std::size_t k = 0; k < n; ++k) out[k] = std::clamp(out[k], 0.0, 1.0);
    }
  }

  // Whether border vertex v may go along its border: two border edges, every edge at it with one
  // or two faces.
  bool border_removable(std::uint32_t v) const {
    for (std::uint32_t x : ring(v))
      if (edge_faces(v, x) > 2) return false;
    return border_neighbours(v).size() == 2;
  }
  // As removal_cost, for a border vertex: its distance to the line of its border neighbours.
  double border_removal_cost(std::uint32_t v) const {
    const std::vector<std::uint32_t> ends = border_neighbours(v);
    const Vec3 along = normalized(x_[ends[1]] - x_[ends[0]]), off = x_[v] - x_[ends[0]];
    const Vec3 d = off - along * dot(off, along);
    double area = 0;
    for (std::uint32_t f : faces_at_[v]) area += 0.5 * length(normal(tri_[3 * f], tri_[3 * f + 1], tri_[3 * f + 2]));
    return dot(d, d) * area;
  }

  // Replaces plan p's old faces by its new ones (the new vertex is w), in the old faces' slots
  // and then in `spare` ones.
  void apply(const Plan& p, std::uint32_t w, std::uint32_t twin, std::span<const std::uint32_t> spare) {
    for (std::uint32_t f : p.old) {
      for (int k = 0; k < 3; ++k) std::erase(faces_at_[tri_[3 * f + k]], f);
      points_of_[f].clear();
    }
    std::vector<std::uint32_t> slot(p.faces.size());
    std::vector<Vec3> first(p.faces.size());
    for (std::size_t i = 0; i < p.faces.size(); ++i) first[i] = first_normal_[p.parent[i]];
    // Each new face is of its parent's material (read before the slots are written).
    std::vector<std::uint32_t>& materials = mesh_.face_materials;
    std::vector<std::uint32_t> material(materials.empty() ? 0 : p.faces.size());
    for (std::size_t i = 0; i < material.size(); ++i) material[i] = materials[p.parent[i]];
    for (std::size_t i = 0; i < p.faces.size(); ++i) {
      slot[i] = i < p.old.size() ? p.old[i] : spare[i - p.old.size()];
      first_normal_[slot[i]] = first[i];
      if (!material.empty()) materials[slot[i]] = material[i];
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = p.faces[i][k] == kNew ? w : p.faces[i][k] == kNewTwin ? twin : p.faces[i][k];
        tri_[3 * slot[i] + k] = v;
        faces_at_[v].push_back(slot[i]);
      }
      score_[slot[i]] = p.scores[i], scored_[slot[i]] = 1, hint_[slot[i]] = p.scores[i].hint, peaked_[slot[i]] = 1;
    }
    for (std::size_t i = 0; i < p.points.size(); ++i) d2_[p.points[i]] = p.d2[i], points_of_[slot[p.nearest[i]]].push_back(p.points[i]);
    for (std::uint32_t f : slot) near_most_[f] = nearest_most(f);
  }

  // Relocations, farthest place first, until one cannot be made or opt_.relocations are.
  std::vector<Relocation> relocate() {
    std::vector<Relocation> made;
    const std::uint32_t nv = std::uint32_t(x_.size());
    // The interior vertices that may go, flattest first.
    // (Listed when the first split is found: most runs have a far place no split mends.)
    std::vector<std::pair<double, std::uint32_t>> flat, flat_border;
    // (Each vertex's kind and cost on the threads, then listed in vertex order: the same lists.)
    const auto list_removable = [&] {
      std::vector<std::uint8_t> kind(nv, 0);  // 1: interior, 2: a border vertex that may go
      std::vector<double> cost(nv);
      for_chunks(nv, kChunk, resolve_threads(opt_.threads), [&](std::size_t, std::size_t begin, std::size_t end) {
        for (std::uint32_t v = std::uint32_t(begin); v < end; ++v) {
          if (held(v) || faces_at_[v].empty()) continue;
          if (interior(v))
            kind[v] = 1, cost[v] = removal_cost(v);
          else if (border_allowed() && border_removable(v))
            kind[v] = 2, cost[v] = border_removal_cost(v);
        }
      });
      for (std::uint32_t v = 0; v < nv; ++v)
        if (kind[v] != 0) (kind[v] == 1 ? flat : flat_border).push_back({cost[v], v});
      std::sort(flat.begin(), flat.end());
      std::sort(flat_border.begin(), flat_border.end());
    };
    std::vector<std::uint8_t> spent(nv, 0);  // new vertices: they stay
    first_normal_.resize(face_count());
    for (std::uint32_t f = 0; f < face_count(); ++f) first_normal_[f] = normalized(normal(tri_[3 * f], tri_[3 * f + 1], tri_[3 * f + 2]));
    peaked_.assign(face_count(), 0);
    dead_face_.assign(face_count(), 0);
    std::size_t faces_given_up = 0, stuck = 0;
    const std::size_t max_given_up = face_count() / kGiveUpShare;
    // What the relocations together may add to E: a share of its input side (the points' squared
    // distances by their areas; the output side is about as large), so that E stays where the
    // contractions and the refit put it while the largest distance falls.
    double budget = 0;
    for (std::size_t q = 0; q < d2_.size(); ++q) budget += weights_[q] * weight_scale_ * d2_[q];
    budget *= 2 * opt_.relocation_budget;
    // A face not scored yet goes by its centroid and edge midpoints. At a border, where the input
    // may end or bend away under the face, that can miss the face's peak by a factor (a dragon
    // face: 0.335e-3 against 0.577e-3, its peak on an edge away from the midpoint), and the pass
    // would end before it came out: border faces from kScoreFrom of the largest are scored first.
    // (Inside, where the input goes on under the face, the estimate is close: scoring those too
    // cost the 1.3M sphere 10-30 % more time for the same output.)
    double top = 0;
    for (std::uint32_t f = 0; f < face_count(); ++f) top = std::max(top, local(f));
    std::vector<std::uint32_t> unscored;
    for (std::uint32_t f = 0; f < face_count(); ++f) {
      const std::uint32_t* t = &tri_[3 * f];
      if (!scored_[f] && local(f) >= kScoreFrom * top &&
          (border_edge(t[0], t[1]) || border_edge(t[1], t[2]) || border_edge(t[2], t[0])))
        unscored.push_back(f);
    }
    for_chunks(unscored.size(), kChunk, resolve_threads(opt_.threads), [&](std::size_t, std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) score_[unscored[i]] = score(unscored[i]), scored_[unscored[i]] = 1;
    });
    // The faces by local(), farthest first; an entry whose face changed since is skipped.
    std::priority_queue<std::pair<double, std::uint32_t>> heap;
    for (std::uint32_t f = 0; f < face_count(); ++f) heap.push({local(f), f});
    // A face scored since it went in (the relocation's own, or a split's neighbour) has a new
    // local(), and its entry is stale: it goes in again with it, or it would never come out.
    rescored_.clear();
    const auto push_rescored = [&] {
      for (std::uint32_t g : rescored_) heap.push({local(g), g});
      rescored_.clear();
    };
    // Collapses tried per relocation: the flattest places are the cheapest, so the first few that
    // are allowed at all are as good as any.
    constexpr std::size_t kCollapsesTried = 32;
    Split split;
    Collapse collapse, candidate;
    while (made.size() < opt_.relocations) {
      std::uint32_t f = UINT32_MAX;
      while (!heap.empty() && f == UINT32_MAX) {
        const auto [value, g] = heap.top();
        heap.pop();
        if (dead_face_[g] || value != local(g)) continue;
        if (!scored_[g]) {
          ensure_scored(g);
          push_rescored();
          continue;
        }
        if (!peaked_[g]) {
          const std::uint32_t* t = &tri_[3 * g];
          climb(x_[t[0]], x_[t[1]], x_[t[2]], score_[g]);
          peaked_[g] = 1;
          heap.push({local(g), g});
          continue;
        }
        f = g;
      }
      // Distances at the rounding's scale (the frame's diagonal is 1) are not far places. A place
      // no split mends is passed over (the next farthest may still be), up to kStuck in a row.
      if (f == UINT32_MAX || local(f) < kNothingFar) break;
      const bool planned = plan_split(f, split);
      push_rescored();
      if (!planned) {
        if (++stuck == kStuck) break;
        continue;
      }
      if (made.empty() && flat.empty() && flat_border.empty()) list_removable();
      const double largest = local(f);
      // The collapse may not make a new far place: its faces stay well below the farthest.
      const double limit = 0.5 * largest;
      std::vector<std::uint32_t>& split_corners = scratch_split_;  // the split's faces' corners
      split_corners.clear();
      for (std::uint32_t g : split.old) split_corners.insert(split_corners.end(), &tri_[3 * g], &tri_[3 * g] + 3);
      const auto near_split = [&](std::uint32_t v) {
        return std::find(split_corners.begin(), split_corners.end(), v) != split_corners.end();
      };
      // The first allowed collapse of the flattest `list`'s vertices (border ones: along the border).
      const auto find_collapse = [&](const std::vector<std::pair<double, std::uint32_t>>& list, bool border) {
        std::size_t tried = 0;
        for (const auto& [cost, u] : list) {
          if (tried == kCollapsesTried) break;
          if (spent[u] || faces_at_[u].empty() || near_split(u)) continue;
          const std::vector<std::uint32_t> around = ring(u);
          if (std::any_of(around.begin(), around.end(), near_split)) continue;
          ++tried;
          if (!plan_collapse(u, limit, border, candidate)) continue;
          const double rise = split.energy + candidate.energy - (split.old_energy + candidate.old_energy);
          if (rise > budget) continue;
          budget -= std::max(rise, 0.0);
          collapse = candidate;
          return true;
        }
        return false;
      };
      bool found = find_collapse(split.border ? flat_border : flat, split.border);
      // A border split with no border vertex to spare takes an interior one, and the output ends a
      // face below its count (a few: the target is a bound, and lod levels stay nested in size).
      bool short_one = false;
      if (!found && split.border && faces_given_up < max_given_up) found = short_one = find_collapse(flat, false);
      if (!found) {
        if (++stuck == kStuck) break;
        continue;
      }
      stuck = 0;
      forget_refused_collapses();
      const std::uint32_t w = collapse.u;
      Relocation r;
      r.removed = w, r.kept = collapse.v, r.point = split.point, r.at_point = split.at_point;
      // The collapse's old faces list the two that die among the rest: its new faces go in the
      // others' slots, the dead ones' are spare.
      std::vector<std::uint32_t> kept_slots;
      std::vector<std::uint32_t> freed;
      for (std::uint32_t g : collapse.old) {
        const std::uint32_t* t = &tri_[3 * g];
        (t[0] == collapse.v || t[1] == collapse.v || t[2] == collapse.v ? freed : kept_slots).push_back(g);
      }
      collapse.old = kept_slots;
      collapse.old.insert(collapse.old.end(), freed.begin(), freed.end());
      apply(collapse, UINT32_MAX, UINT32_MAX, {});
      faces_at_[w].clear();
      x_[w] = split.y;
      note_moved(w);
      spent[w] = 1;
      // (Held so: no later split joins it to a place it may share with another vertex.)
      held_[w] = caller_held_[w] = split.hold_new;
      if (split.crack) {
        // The new vertex's twin, on the crack's other side: a vertex more.
        r.added = std::uint32_t(x_.size());
        x_.push_back(split.y), held_.push_back(1), twin_.push_back(w), faces_at_.emplace_back(), spent.push_back(1);
        caller_held_.push_back(1), alike_.push_back(UINT32_MAX);
        held_[w] = 1, twin_[w] = r.added;
        note_moved(r.added);
      }
      apply(split, w, r.added, freed);
      if (!mesh_.attributes.empty()) {
        set_values(w, split.from, split.share);
        if (r.added != UINT32_MAX) set_values(r.added, split.twin_from, split.share_twin);
      }
      const std::size_t reused = split.faces.size() - split.old.size();
      for (std::size_t k = 0; k < reused; ++k) r.reused[k] = freed[k], r.parent[k] = split.parent[split.old.size() + k];
      if (short_one) {
        r.dropped = freed[1];
        dead_face_[freed[1]] = 1;
        ++faces_given_up;
      }
      for (std::uint32_t g : collapse.old) heap.push({local(g), g});
      for (std::uint32_t g : split.old) heap.push({local(g), g});
      for (std::uint32_t g : freed) heap.push({local(g), g});
      made.push_back(r);
    }
    return made;
  }

  Mesh& mesh_;
  const Frame frame_;
  const SurfaceDistance& surface_;
  std::span<const double> points_, weights_;
  const FarRepairOptions& opt_;
  const double cos_turn_;
  const double weight_scale_;  // model area to the frame's
  struct Channel {
    const std::vector<double>* input;   // per input vertex
    const std::vector<double>* output;  // per output vertex
    std::uint32_t components;
    std::uint32_t first;  // its first component among a sample's values (ValueSamples::values)
    double weight2;       // the metric's weight, squared
  };
  std::vector<Channel> channels_;                    // the attributes that judge flips and moves
  std::uint32_t value_width_ = 0;                    // their components, all together
  ContextBoxes scratch_boxes_;                       // sample_values' context faces' boxes
  std::vector<double> scratch_gaps_;                 // and a sample's distances to them
  ValueSamples scratch_samples_;                     // the input's surface round a change (sample_values)
  std::vector<std::uint32_t> scratch_on_;            // per point of a change, its face before it
  std::vector<Vec3> x_;                              // output positions in the frame
  std::vector<std::uint8_t> held_;                   // per vertex: its edges stay
  std::vector<std::uint32_t> twin_;                  // per vertex, the other vertex at its position (a pair only)
  std::vector<std::uint8_t> caller_held_;            // per vertex: held by the caller (or a relocation)
  std::vector<std::uint32_t> alike_;                 // per vertex, its index in places_ (UINT32_MAX: alone)
  std::vector<std::vector<std::uint32_t>> places_;   // vertices that share a position
  std::vector<std::uint32_t> tri_;                   // output faces (3 per face), flipped in place
  std::vector<std::vector<std::uint32_t>> faces_at_;  // per vertex, the faces that have it
  std::vector<FaceScore> score_;                     // per face, its samples (where scored_)
  std::vector<std::uint8_t> scored_;                 // per face: score_ is exact
  std::vector<std::uint8_t> dead_face_;              // per face slot: dropped by a relocation (compacted at the end)
  std::vector<std::uint32_t> rescored_;              // faces ensure_scored scored (relocate's heap takes them)
  std::vector<std::pair<double, std::uint32_t>> border_by_x_;  // the input's border points by x (plan_split)
  std::vector<std::uint8_t> peaked_;                 // per face: score_.most climbed to its peak (relocations)
  std::vector<Vec3> first_normal_;                   // per face slot, its line's normal when the relocations began
  std::vector<double> near_;                         // per face, its centroid's and edge midpoints' largest
  std::vector<std::uint32_t> hint_;                  // per face, a face of the input near it
  std::vector<std::uint8_t> found_border_;           // border_points(), when the caller gave none
  double largest_ = 0;                               // the largest distance both ways, at the start (scanned)
  std::vector<std::vector<std::uint32_t>> points_of_;  // per face, the input points closest to it
  std::vector<double> near_most_;                    // per face, the largest of those points' distances
  std::vector<double> d2_;                           // per point, its squared distance to its face
  std::vector<std::uint32_t> moved_;                 // vertices moved (ascending, once each)
  std::vector<std::uint32_t> scratch_points_, scratch_context_, scratch_near_, scratch_split_;
  std::vector<BoxedTriangle> scratch_planned_, scratch_rest_, scratch_old_;  // input_stays_near
  std::unordered_map<std::uint64_t, double> refused_below_;  // plan_collapse: 2 u + border -> limit
  std::vector<std::uint32_t> scratch_nearest_;  // per point of a flip or move, its nearest new face
  std::vector<double> scratch_d2_;
};

}  // namespace

std::vector<std::uint8_t> points_on_border(std::span<const std::uint32_t> indices,
                                           std::span<const std::uint32_t> point_source, unsigned threads) {
  const std::span<const std::uint32_t> faces = indices.first(indices.size() - indices.size() % 3);
  std::size_t vertex_count = 0;
  for (std::uint32_t v : faces) vertex_count = std::max<std::size_t>(vertex_count, std::size_t(v) + 1);
  const std::vector<std::uint8_t> border = border_vertices(faces, vertex_count, threads);
  std::vector<std::uint8_t> on(point_source.size(), 0);
  for (std::size_t p = 0; p < point_source.size(); ++p)
    on[p] = point_source[p] < vertex_count && border[point_source[p]];
  return on;
}

FarRepairResult repair_far_places(Mesh& approx, const Frame& frame, const SurfaceDistance& surface,
                              std::span<const double> points, std::span<const double> weights,
                              const FarRepairOptions& options) {
  if (approx.face_count() < 2 || surface.empty()) return {};
  return Repairer(approx, frame, surface, points, weights, options).run();
}

}  // namespace qem::core
