// Iterative pair contraction (GH97 §4), the heart of qem.
//
// Pipeline (each step one function below):
//   prepare_input        validate, drop degenerate and duplicate faces, normalise the frame
//   rebuild_face_lists   per-vertex face lists (again at the start of each pass)
//   compute_quadrics     GH97 §5 fundamental quadrics, weighted (HG99 §2), + boundary planes (GH97 §6)
//   select_pairs         GH97 §3.2: edges + pairs closer than t
//   run_greedy           cost every pair, heap them, then repeatedly: pop the cheapest, check it
//                        (topology, inversion, error limit), contract it, re-cost the new vertex's pairs
//   run_passes           the default: rank all pairs, make the cheapest independent ones, repeat;
//                        each band of a pass is made region by region (make_band), on all threads
//   simplify_and_refit   with refit_rounds > 0, the output's vertices are then refitted to the
//                        input surface (src/refit, Hoppe et al. 1993) once the arrays above are freed
//
// Everything runs in a normalised frame (centred, bounding-box diagonal 1), so every tolerance is
// relative and the result does not depend on the model's position or scale; vertices that never
// move are written back with their exact input coordinates.
#include "qem/simplify.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <exception>
#include <future>
#include <limits>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>

#include "check_mesh.h"
#include "core/indexed_heap.h"
#include "core/invariant_checks.h"
#include "core/placement.h"
#include "core/quadric.h"
#include "core/radix_sort.h"
#include "core/spatial_order.h"
#include "core/valid_pairs.h"
#include "core/vertex_lists.h"
#include "qem/error.h"
#include "refit/refit_points.h"

namespace qem {

namespace {

using namespace core;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Heap keys are floats (24 significant bits). The same model scaled or moved gives costs that
// differ only by rounding noise (~1e-16 relative); rounded to float they tie, ties break on the
// pair id, and the contraction order (and so the output) does not depend on the model's scale or
// position. It also halves the heap, whose cache misses dominate the contraction loop.
double round_key(double cost) { return double(float(cost)); }

enum PairState : std::uint8_t {
  kInHeap,   // candidate, keyed in the heap
  kBlocked,  // rejected at its last check (topology, inversion, error limit); retried when its
             // neighbourhood changes
  kLocked,   // can never be contracted (both ends on a locked border)
  kDead,     // contracted, or merged into a duplicate
};

class Simplifier {
 public:
  Simplifier(MeshView input, const SimplifyOptions& options) : in_(input), opt_(options) {}
  /// The input's index array, released once prepare_input has copied the faces (simplify(Mesh&&)).
  std::vector<std::uint32_t>* consumed_indices = nullptr;
  /// Filled with the input's vertex areas when a refit follows (see simplify_and_refit).
  std::vector<double>* refit_weights = nullptr;
  /// Filled, when a refit follows, with the output vertex each input vertex was contracted into
  /// (UINT32_MAX: none), where the refit's search for its closest face starts.
  std::vector<std::uint32_t>* refit_map = nullptr;

  SimplifyResult run();

 private:
  // --- setup --------------------------------------------------------------------------------
  void prepare_input();
  void rebuild_face_lists();
  void rebuild_pair_lists();
  void compute_quadrics();
  void select_pairs(std::vector<Edge> edges);
  void resolve_targets();

  // What one thread needs to make contractions: its own scratch space, stamps and counters (the
  // shared counters absorb them). Threads work on disjoint parts of the mesh (see make_band), so
  // nothing else they write is shared.
  struct Worker {
    std::uint32_t stamp = 0;  // last stamp used in mark_; every stamp is used once in a run
    std::vector<std::uint32_t> scratch, scratch2;
    std::size_t faces_killed = 0, vertices_removed = 0, contractions = 0;
    std::size_t blocked_topology = 0, blocked_inversion = 0, blocked_error = 0;
    double max_error = 0;
    std::uint32_t last_kept = 0, last_removed = 0;  // of the last contraction made
  };
  void absorb(Worker& w);

  // --- the two orders of contraction ------------------------------------------------------------
  void run_greedy();
  void run_passes();
  bool make_band(const std::uint32_t* band, std::size_t count);
  void find_region_cut();
  bool ready_to_contract(std::uint32_t p);
  bool try_contract(std::uint32_t p, Worker& w);
  bool report_progress();
  void prefetch_for_contraction(const std::uint32_t* pairs, std::size_t count, std::size_t i) const;
  void recost_dirty_pairs();
  void renumber_densely();
  void check_lists() const;
  unsigned thread_count() const {
    return opt_.threads > 0 ? opt_.threads : std::max(1u, std::thread::hardware_concurrency());
  }
  // Two independent pieces of work: side by side when there are threads (the first on a helper
  // thread), else one after the other. Either way the result is the same.
  template <class First, class Second>
  void side_by_side(First first, Second second) {
    if (thread_count() < 2) {
      first();
      second();
      return;
    }
    std::future<void> first_done = std::async(std::launch::async, first);
    second();
    first_done.get();
  }

  // --- the contraction loop ------------------------------------------------------------------
  bool pair_cost(std::uint32_t p, double& cost);
  void cost_pair(std::uint32_t p);
  bool is_edge_and_link_ok(std::uint32_t a, std::uint32_t b, bool& is_edge, Worker& w);
  bool flips(std::uint32_t a, std::uint32_t b, const Vec3& target);
  bool placement_for(std::uint32_t p, Quadric& q, Placed& placed);
  void contract(std::uint32_t p, const Quadric& q, const Vec3& target, Worker& w);
  void block(std::uint32_t p);
  void record_contraction(double error, const Worker& w);
  bool kill_if_coincident(std::uint32_t f, std::size_t own, Worker& w);
  void follow_contractions(const std::vector<std::uint32_t>& to, std::size_t vertex_count);
  void unblock_around(std::uint32_t v);
  // Calls f(r) for every pair r in the list of v as it is now: in a pass, a vertex's stored list
  // is the one of the pass's start, and a survivor's pairs now are its own and those of the
  // vertex it absorbed (merged_from_). Dead pairs are included: callers skip them.
  template <class F>
  void for_each_pair_of(std::uint32_t v, F f) const {
    for (std::uint32_t r : vertex_pairs_[v]) f(r);
    if (passes_ && merged_from_[v] != kNoVertex)
      for (std::uint32_t r : vertex_pairs_[merged_from_[v]]) f(r);
  }
  void forget(std::uint32_t p) {
    if (!passes_) heap_.remove(p);
  }
  bool done() const { return faces_alive_ <= target_faces_ || vertices_alive_ <= target_vertices_; }
  double normalized_error(double q_error, double weight) const {
    return weight > 0 ? std::sqrt(q_error / weight) : std::sqrt(q_error);
  }
  void kill_face(std::uint32_t f, Worker& w) {
    face_alive_[f] = 0;
    ++w.faces_killed;
    if (opt_.record) opt_.record->dead_faces.push_back(face_source_[f]);
  }
  std::uint32_t other_end(std::uint32_t p, std::uint32_t v) const {
    return pairs_[p].v[0] == v ? pairs_[p].v[1] : pairs_[p].v[0];
  }
  bool face_has(std::uint32_t f, std::uint32_t v) const {
    const std::uint32_t* t = &tri_[3 * std::size_t(f)];
    return t[0] == v || t[1] == v || t[2] == v;
  }
  Vec3 face_normal(const std::uint32_t* t, std::uint32_t moved, const Vec3& to) const {
    const Vec3& p0 = t[0] == moved ? to : pos_[t[0]];
    const Vec3& p1 = t[1] == moved ? to : pos_[t[1]];
    const Vec3& p2 = t[2] == moved ? to : pos_[t[2]];
    return cross(p1 - p0, p2 - p0);
  }
  SimplifyResult build_output();
  /// A vertex's position in the input frame: exact input coordinates if it never moved.
  Vec3 output_position(std::uint32_t v) const {
    if (moved_[v]) return pos_[v] * scale_ + center_;
    const double* p = &in_.positions[3 * std::size_t(source_vertex_[v])];
    return {p[0], p[1], p[2]};
  }

  MeshView in_;
  const SimplifyOptions& opt_;
  bool passes_ = opt_.scheme == Scheme::Passes;

  // Normalised frame: p_work = (p_in - center_) / scale_.
  Vec3 center_;
  double scale_ = 1;

  std::vector<Vec3> pos_;
  std::vector<Quadric> quadric_;
  std::vector<std::uint8_t> boundary_, moved_, has_blocked_;
  // Set on both ends of a contracted threshold pair and inherited through merges: the region is
  // an aggregation joint, non-manifold by design (GH97 §3.2), where the link condition does not apply.
  std::vector<std::uint8_t> aggregated_;
  std::vector<std::uint32_t> tri_;  // 3 per working face
  std::vector<std::uint32_t> face_source_;    // input face index of each working face
  std::vector<std::uint32_t> source_vertex_;  // input vertex index of each working vertex
  std::vector<std::uint8_t> face_alive_;
  VertexLists vertex_faces_, vertex_pairs_;

  // One record per valid pair, packed so that a pair costs one cache line visit.
  struct PairRecord {
    std::uint32_t v[2];
    std::uint8_t state;
    std::uint8_t is_virtual;  // created by the threshold t (GH97 §3.2 rule 2), not an edge
  };
  std::vector<PairRecord> pairs_;
  // The current cost of each pair. Its heap key may be lower: a cost that rises (as it nearly
  // always does after a contraction, since quadrics only grow) is not sifted down the heap; the
  // pair is re-keyed when it reaches the top. Keys are lower bounds and the popped pair's key is
  // verified current, so the order is exactly GH97's greedy order at a fraction of the heap work.
  // Costs are rounded to float (round_key), so float storage is exact.
  std::vector<float> cost_;
  IndexedHeap heap_;
  // Passes: a pair whose cost must be recomputed before the next ranking, and the pass in which
  // each vertex last took part in a contraction (each vertex contracts at most once a pass, so
  // every other cost ranked in the pass stays exact).
  std::vector<std::uint8_t> dirty_;
  std::vector<std::uint32_t> touched_in_pass_;
  // Passes: the vertex lists are rebuilt at the start of each pass and not written during it. A
  // contraction renames its removed end in the faces and pairs themselves, so every list but the
  // survivor's stays right; the survivor's is its own plus that of the vertex it absorbed, which
  // is recorded here (kNoVertex: none), and it is never contracted again in the pass.
  static constexpr std::uint32_t kNoVertex = 0xffffffffu;
  std::vector<std::uint32_t> merged_from_;
  // The contraction map, kept only for a refit (refit_map): per input vertex, the vertex it is part
  // of now (kNoVertex: none), as of the last renumbering; per vertex, the one it was contracted
  // into since then (kNoVertex: none). See follow_contractions.
  std::vector<std::uint32_t> home_, absorbed_into_;

  // Stamps for set membership without clearing (one array, fresh stamp per query).
  std::vector<std::uint32_t> mark_;
  Worker main_;  // the worker of every contraction made on the calling thread

  // Passes: the vertices split into kRegions ranges of ids (ids follow the Morton order, so each
  // range is a compact part of the surface). cut_ marks every vertex with a pair to another
  // region; near_cut_ marks the cut and its neighbours (or more: a superset is safe).
  static constexpr std::uint32_t kRegions = 8;
  std::uint64_t region_scale_ = 0;  // floor(2^40 kRegions / vertex count): no division per lookup
  std::uint32_t region_of(std::uint32_t v) const { return std::uint32_t((v * region_scale_) >> 40); }
  std::vector<std::uint8_t> cut_, near_cut_;
  void mark_cut(std::uint32_t v);
  void mark_neighbours_near(std::uint32_t v);
  void update_cut_after(std::uint32_t survivor);

  std::size_t faces_alive_ = 0, vertices_alive_ = 0;
  std::size_t target_faces_ = 0, target_vertices_ = 0;
  double max_error_norm_ = kInf;   // error limit in the normalised frame
  double cos_max_turn_ = 0;
  std::size_t dropped_degenerate_ = 0, dropped_duplicate_ = 0;
  std::size_t blocked_by_error_ = 0, blocked_by_topology_ = 0, blocked_by_inversion_ = 0;
  std::size_t virtual_pairs_ = 0;
  std::size_t next_progress_ = 0;
  double max_error_norm_done_ = 0;

  SimplifyResult result_;
};

// ---------------------------------------------------------------------------------------------
// Setup
// ---------------------------------------------------------------------------------------------

void Simplifier::prepare_input() {
  const std::size_t nv = in_.vertex_count(), nf = in_.face_count();
  check_mesh(in_, "input");

  // Referenced vertices only: unreferenced ones take no part and are dropped from the output.
  // Degenerate faces (a repeated corner) carry no plane and no area: dropped too.
  std::vector<std::uint8_t> referenced(nv, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t* t = &in_.indices[3 * f];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      ++dropped_degenerate_;
      continue;
    }
    referenced[t[0]] = referenced[t[1]] = referenced[t[2]] = 1;
  }
  std::vector<std::uint32_t> used;
  for (std::uint32_t v = 0; v < nv; ++v)
    if (referenced[v]) used.push_back(v);

  // Normalised frame from the referenced vertices' bounding box.
  double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
  for (std::uint32_t v : used)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], in_.positions[3 * v + k]);
      hi[k] = std::max(hi[k], in_.positions[3 * v + k]);
    }
  if (!used.empty()) {
    // Beyond 1e300 the quadrics (squared distances times areas) overflow double precision.
    for (int k = 0; k < 3; ++k)
      if (!(std::fabs(lo[k]) <= 1e300 && std::fabs(hi[k]) <= 1e300))
        throw Error("coordinates beyond 1e300 in magnitude cannot be simplified in double precision");
    center_ = {lo[0] / 2 + hi[0] / 2, lo[1] / 2 + hi[1] / 2, lo[2] / 2 + hi[2] / 2};
    scale_ = length(Vec3(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
    if (!(scale_ > 0) || !std::isfinite(scale_)) scale_ = 1;
  }
  auto normalized = [&](std::uint32_t v) {
    return (Vec3(in_.positions[3 * v], in_.positions[3 * v + 1], in_.positions[3 * v + 2]) - center_) * (1.0 / scale_);
  };

  // Internal numbering along a Morton curve (see spatial_order.h); source_vertex_ maps back.
  source_vertex_ = morton_order(used.size(), [&](std::size_t i) { return normalized(used[i]); });
  for (std::uint32_t& v : source_vertex_) v = used[v];
  std::vector<std::uint32_t>().swap(used);
  const std::uint32_t n = std::uint32_t(source_vertex_.size());
  std::vector<std::uint32_t> internal(nv, 0);
  pos_.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    internal[source_vertex_[i]] = i;
    pos_[i] = normalized(source_vertex_[i]);
  }

  // Faces bucketed by their lowest internal vertex (a counting sort: neighbouring faces end up
  // together in memory). Duplicates (same three vertices, either orientation) share a bucket:
  // they would count their plane twice and survive as duplicates in the output, so only the
  // first in input order is kept.
  std::vector<std::uint32_t> bucket_start(n + 1, 0);
  auto sorted_corners = [&](std::size_t f) {
    std::array<std::uint32_t, 3> t{internal[in_.indices[3 * f]], internal[in_.indices[3 * f + 1]],
                                   internal[in_.indices[3 * f + 2]]};
    std::sort(t.begin(), t.end());
    return t;
  };
  auto degenerate = [&](std::size_t f) {
    const std::uint32_t* t = &in_.indices[3 * f];
    return t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
  };
  for (std::size_t f = 0; f < nf; ++f)
    if (!degenerate(f)) ++bucket_start[sorted_corners(f)[0] + 1];
  for (std::uint32_t i = 0; i < n; ++i) bucket_start[i + 1] += bucket_start[i];
  std::vector<std::uint32_t> bucketed(bucket_start[n]);
  {
    std::vector<std::uint32_t> fill(bucket_start.begin(), bucket_start.end() - 1);
    for (std::size_t f = 0; f < nf; ++f)
      if (!degenerate(f)) bucketed[fill[sorted_corners(f)[0]]++] = std::uint32_t(f);
  }
  tri_.reserve(3 * bucketed.size());
  face_source_.reserve(bucketed.size());
  std::vector<std::pair<std::array<std::uint32_t, 3>, std::uint32_t>> bucket;
  for (std::uint32_t i = 0; i < n; ++i) {
    bucket.clear();
    for (std::uint32_t k = bucket_start[i]; k < bucket_start[i + 1]; ++k)
      bucket.push_back({sorted_corners(bucketed[k]), bucketed[k]});
    std::sort(bucket.begin(), bucket.end());
    for (std::size_t k = 0; k < bucket.size(); ++k) {
      if (k > 0 && bucket[k].first == bucket[k - 1].first) {
        ++dropped_duplicate_;
        continue;
      }
      const std::uint32_t f = bucket[k].second;
      for (int c = 0; c < 3; ++c) tri_.push_back(internal[in_.indices[3 * std::size_t(f) + c]]);
      face_source_.push_back(f);
    }
  }
  faces_alive_ = face_source_.size();
  face_alive_.assign(faces_alive_, 1);

  vertices_alive_ = n;
  moved_.assign(n, 0);
  boundary_.assign(n, 0);
  has_blocked_.assign(n, 0);
  aggregated_.assign(n, 0);
  mark_.assign(n, 0);
  result_.input_faces = faces_alive_;
  result_.input_vertices = vertices_alive_;
}

// Each vertex's live faces, in face order.
void Simplifier::rebuild_face_lists() {
  vertex_faces_.rebuild(pos_.size(), [&](auto emit) {
    for (std::uint32_t f = 0; f < face_alive_.size(); ++f)
      if (face_alive_[f])
        for (int k = 0; k < 3; ++k) emit(tri_[3 * std::size_t(f) + k], f);
  });
}

// Each vertex's pairs that are not dead, in pair order.
void Simplifier::rebuild_pair_lists() {
  vertex_pairs_.rebuild(pos_.size(), [&](auto emit) {
    for (std::uint32_t p = 0; p < pairs_.size(); ++p)
      if (pairs_[p].state != kDead) emit(pairs_[p].v[0], p), emit(pairs_[p].v[1], p);
  });
}

void Simplifier::compute_quadrics() {
  quadric_.assign(pos_.size(), Quadric{});
  for (std::uint32_t f = 0; f < face_source_.size(); ++f) {
    const std::uint32_t* t = &tri_[3 * std::size_t(f)];
    Vec3 n = cross(pos_[t[1]] - pos_[t[0]], pos_[t[2]] - pos_[t[0]]);
    double len = length(n);
    if (!(len > 0)) continue;  // zero-area face: no plane (GH97 §5 needs a unit normal)
    n = n * (1.0 / len);
    double d = -dot(n, pos_[t[0]]);
    switch (opt_.weighting) {
      case Weighting::Area: {  // HG99 §2: the quadric integrates squared distance over the area
        Quadric q = Quadric::plane(n, d, len / 2);
        for (int k = 0; k < 3; ++k) quadric_[t[k]] += q;
        break;
      }
      case Weighting::Uniform: {  // GH97 §5
        Quadric q = Quadric::plane(n, d, 1);
        for (int k = 0; k < 3; ++k) quadric_[t[k]] += q;
        break;
      }
      case Weighting::Angle:  // each corner weighs its plane by its own angle
        for (int k = 0; k < 3; ++k) {
          Vec3 e1 = pos_[t[(k + 1) % 3]] - pos_[t[k]], e2 = pos_[t[(k + 2) % 3]] - pos_[t[k]];
          double angle = std::atan2(length(cross(e1, e2)), dot(e1, e2));
          quadric_[t[k]] += Quadric::plane(n, d, angle);
        }
        break;
    }
  }
}

// `edges`: unique_edges of the working mesh.
void Simplifier::select_pairs(std::vector<Edge> edges) {
  // Boundary edges (one incident face): mark their vertices, and add GH97 §6's constraint plane
  // through the edge, perpendicular to its face, weighted by the penalty. The weight grows with
  // the squared edge length so that it stays in proportion to the area-weighted face quadrics at
  // every resolution and scale.
  for (const Edge& e : edges) {
    if (e.faces != 1) continue;
    boundary_[e.lo] = boundary_[e.hi] = 1;
    if (!(opt_.boundary_weight > 0)) continue;
    std::uint32_t face = 0;
    for (std::uint32_t f : vertex_faces_[e.lo])
      if (face_has(f, e.hi)) face = f;
    const std::uint32_t* t = &tri_[3 * std::size_t(face)];
    Vec3 n = cross(pos_[t[1]] - pos_[t[0]], pos_[t[2]] - pos_[t[0]]);
    Vec3 edge = pos_[e.hi] - pos_[e.lo];
    Vec3 m = cross(edge, n);
    double len = length(m);
    if (!(len > 0)) continue;
    m = m * (1.0 / len);
    double w = opt_.boundary_weight * (opt_.weighting == Weighting::Area ? dot(edge, edge) : 1.0);
    Quadric q = Quadric::plane(m, -dot(m, pos_[e.lo]), w);
    q.weight = 0;  // a constraint, not surface: it must not dilute the reported mean distance
    quadric_[e.lo] += q;
    quadric_[e.hi] += q;
  }

  std::vector<std::pair<std::uint32_t, std::uint32_t>> virtual_pairs;
  if (opt_.threshold > 0) {
    double t = opt_.threshold_is_relative ? opt_.threshold : opt_.threshold / scale_;
    std::vector<std::uint32_t> candidates;
    for (std::uint32_t v = 0; v < pos_.size(); ++v) candidates.push_back(v);
    virtual_pairs = close_pairs(pos_, candidates, t, edges, kMaxThresholdPairsPerVertex);
  }
  virtual_pairs_ = virtual_pairs.size();

  const std::size_t np = edges.size() + virtual_pairs.size();
  if (np >= 0xffffffffu) throw Error("too many pairs for 32-bit pair ids");
  pairs_.resize(np);
  for (std::size_t i = 0; i < edges.size(); ++i) pairs_[i] = {{edges[i].lo, edges[i].hi}, kInHeap, 0};
  for (std::size_t i = 0; i < virtual_pairs.size(); ++i)
    pairs_[edges.size() + i] = {{virtual_pairs[i].first, virtual_pairs[i].second}, kInHeap, 1};
  std::vector<Edge>().swap(edges);
  rebuild_pair_lists();
}

void Simplifier::resolve_targets() {
  const std::size_t nf = faces_alive_;
  bool any = false;
  target_faces_ = 0;
  if (opt_.target_faces > 0) target_faces_ = opt_.target_faces, any = true;
  if (opt_.target_ratio > 0) {
    if (!(opt_.target_ratio <= 1)) throw Error("target ratio must be in (0, 1]");
    std::size_t t = std::size_t(std::floor(opt_.target_ratio * double(nf)));
    target_faces_ = any ? std::max(target_faces_, t) : t;
    any = true;
  }
  target_vertices_ = 0;
  if (opt_.target_vertices > 0) target_vertices_ = opt_.target_vertices, any = true;
  if (std::isfinite(opt_.max_error)) {
    if (opt_.max_error < 0) throw Error("max error must not be negative");
    max_error_norm_ = opt_.max_error_is_relative ? opt_.max_error : opt_.max_error / scale_;
    any = true;
  }
  if (!any) throw Error("no stop criterion: give a face, ratio, vertex or error target");
  if (opt_.max_normal_turn_degrees <= 0 || opt_.max_normal_turn_degrees >= 90)
    throw Error("the inversion angle limit must be in (0, 90) degrees");
  if (opt_.threshold < 0) throw Error("threshold must not be negative");
  if (opt_.boundary_weight < 0) throw Error("boundary weight must not be negative");
  refit_detail::check_options(refit_options(opt_));
  cos_max_turn_ = std::cos(opt_.max_normal_turn_degrees * 3.14159265358979323846 / 180.0);
}

// ---------------------------------------------------------------------------------------------
// Costs and checks
// ---------------------------------------------------------------------------------------------

// The quadric and placement of pair p, honouring --lock-border. False if the pair can never move.
bool Simplifier::placement_for(std::uint32_t p, Quadric& q, Placed& placed) {
  std::uint32_t a = pairs_[p].v[0], b = pairs_[p].v[1];
  q = quadric_[a] + quadric_[b];
  if (opt_.lock_border && (boundary_[a] || boundary_[b])) {
    if (boundary_[a] && boundary_[b]) return false;
    const Vec3& fixed = boundary_[a] ? pos_[a] : pos_[b];
    placed = {fixed, q.evaluate(fixed)};
    return true;
  }
  placed = place(q, pos_[a], pos_[b], opt_.placement);
  return true;
}

// The key of pair p in the heap: the quadric error at its placement (GH97 §4), plus a penalty that
// sorts it after every clean contraction when it would flip a face and inversions are penalised.
bool Simplifier::pair_cost(std::uint32_t p, double& cost) {
  Quadric q;
  Placed placed;
  if (!placement_for(p, q, placed)) return false;
  cost = placed.error;
  if (opt_.inversion == InversionPolicy::Penalize && flips(pairs_[p].v[0], pairs_[p].v[1], placed.position))
    cost += q.weight > 0 ? q.weight : 1;  // as if moved by a whole diagonal
  cost = round_key(cost);
  return true;
}

void Simplifier::cost_pair(std::uint32_t p) {
  if (passes_) {  // ranked again at the start of the next pass
    pairs_[p].state = kInHeap;
    dirty_[p] = 1;
    return;
  }
  double c;
  if (!pair_cost(p, c)) {
    pairs_[p].state = kLocked;
    forget(p);
    return;
  }
  pairs_[p].state = kInHeap;
  cost_[p] = float(c);
  if (!heap_.contains(p) || c < heap_.key_of(p)) heap_.update(p, c);
}

// GH97 §6 "preventing mesh inversion": a face around a or b (that survives the contraction) whose
// normal turns by more than the limit, or that would lose its area, forbids the contraction.
bool Simplifier::flips(std::uint32_t a, std::uint32_t b, const Vec3& target) {
  for (std::uint32_t end = 0; end < 2; ++end) {
    std::uint32_t v = end == 0 ? a : b, other = end == 0 ? b : a;
    for (std::uint32_t f : vertex_faces_[v]) {
      if (!face_alive_[f] || face_has(f, other)) continue;
      const std::uint32_t* t = &tri_[3 * std::size_t(f)];
      Vec3 before = face_normal(t, v, pos_[v]);
      Vec3 after = face_normal(t, v, target);
      double lb = dot(before, before), la = dot(after, after);
      if (!(lb > 0)) continue;  // a face that was already flat cannot flip
      if (!(la > 1e-24 * lb)) return true;
      double d = dot(before, after);
      if (d <= 0 || d * d < cos_max_turn_ * cos_max_turn_ * la * lb) return true;
    }
  }
  return false;
}

// Whether (a, b) is an edge, and if so whether collapsing it keeps the surface's topology
// (the link condition of Dey et al.; the check GH97 leaves to the implementer): the vertices
// adjacent to both a and b must be exactly the opposite corners of the faces on edge ab, the
// collapse must not stack two faces onto the same three vertices, and an interior edge whose two
// ends both lie on a border must not pinch the border.
bool Simplifier::is_edge_and_link_ok(std::uint32_t a, std::uint32_t b, bool& is_edge, Worker& w) {
  const std::uint32_t s_nbr = ++w.stamp, s_opp = ++w.stamp;
  std::size_t shared = 0;
  for (std::uint32_t f : vertex_faces_[a]) {
    if (!face_alive_[f]) continue;
    const std::uint32_t* t = &tri_[3 * std::size_t(f)];
    if (face_has(f, b)) {
      ++shared;
      for (int k = 0; k < 3; ++k)
        if (t[k] != a && t[k] != b) mark_[t[k]] = s_opp;
    } else {
      for (int k = 0; k < 3; ++k)
        if (t[k] != a && mark_[t[k]] != s_opp) mark_[t[k]] = s_nbr;
    }
  }
  is_edge = shared > 0;
  if (!is_edge || !opt_.preserve_topology || aggregated_[a] || aggregated_[b]) return true;
  if (shared == 2 && boundary_[a] && boundary_[b]) return false;  // would pinch the border
  // Neighbours of b that are also neighbours of a but not opposite corners break the link condition.
  for (std::uint32_t f : vertex_faces_[b]) {
    if (!face_alive_[f] || face_has(f, a)) continue;
    const std::uint32_t* t = &tri_[3 * std::size_t(f)];
    int opp_corners = 0;
    for (int k = 0; k < 3; ++k) {
      std::uint32_t x = t[k];
      if (x == b) continue;
      if (mark_[x] == s_nbr) return false;
      if (mark_[x] == s_opp) ++opp_corners;
    }
    // A face (b, x, y) with x, y both opposite corners: if a also has a face (a, x, y), the
    // collapse would stack two faces on the same vertices (the tetrahedron case).
    if (opp_corners == 2) {
      std::uint32_t x = t[0] == b ? t[1] : t[0], y = t[2] == b ? t[1] : t[2];
      for (std::uint32_t g : vertex_faces_[a])
        if (face_alive_[g] && face_has(g, x) && face_has(g, y)) return false;
    }
  }
  return true;
}

// Face f (now on a) against a's own faces w.scratch[0..own): on the same three vertices with the
// same orientation it is a duplicate and dies; with the opposite orientation the two are the
// touching walls of two aggregated parts (GH97 §3.2, Fig. 3) and both die, like glued faces.
bool Simplifier::kill_if_coincident(std::uint32_t f, std::size_t own, Worker& w) {
  const std::uint32_t* t = &tri_[3 * std::size_t(f)];
  for (std::size_t i = 0; i < own; ++i) {
    const std::uint32_t g = w.scratch[i];
    if (!face_alive_[g] || !(face_has(g, t[0]) && face_has(g, t[1]) && face_has(g, t[2]))) continue;
    const std::uint32_t* u = &tri_[3 * std::size_t(g)];
    int k = 0;
    while (u[k] != t[0]) ++k;
    const bool same_orientation = u[(k + 1) % 3] == t[1];
    kill_face(f, w);
    if (!same_orientation) kill_face(g, w);
    return true;
  }
  return false;
}

// Appends the contraction just made to the log; `w.last_kept` / `w.last_removed` are set by
// contract(), the dead faces were appended by kill_face().
void Simplifier::record_contraction(double error, const Worker& w) {
  ContractionLog& log = *opt_.record;
  log.kept.push_back(source_vertex_[w.last_kept]);
  log.removed.push_back(source_vertex_[w.last_removed]);
  const Vec3 p = output_position(w.last_kept);
  log.position.insert(log.position.end(), {p.x, p.y, p.z});
  log.error.push_back(error);
  log.dead_begin.push_back(std::uint32_t(log.dead_faces.size()));
}

void Simplifier::block(std::uint32_t p) {
  pairs_[p].state = kBlocked;
  has_blocked_[pairs_[p].v[0]] = has_blocked_[pairs_[p].v[1]] = 1;
}

// The neighbourhood of v changed: pairs of v's neighbours that were rejected get another chance.
void Simplifier::unblock_around(std::uint32_t v) {
  for_each_pair_of(v, [&](std::uint32_t p) {
    if (pairs_[p].state == kDead) return;
    std::uint32_t o = other_end(p, v);
    if (!has_blocked_[o]) return;
    has_blocked_[o] = 0;
    for_each_pair_of(o, [&](std::uint32_t q) {
      if (pairs_[q].state == kBlocked) cost_pair(q);
    });
  });
}

// ---------------------------------------------------------------------------------------------
// Contraction (GH97 §4 step 5): (a, b) -> a at `target`.
// ---------------------------------------------------------------------------------------------

void Simplifier::contract(std::uint32_t p, const Quadric& q, const Vec3& target, Worker& w) {
  std::uint32_t a = pairs_[p].v[0], b = pairs_[p].v[1];
  // When the target is one of the ends (endpoint placement, a locked border vertex), that end
  // survives, so its exact input coordinates reach the output untouched.
  const auto same = [](const Vec3& x, const Vec3& y) { return x.x == y.x && x.y == y.y && x.z == y.z; };
  if (same(target, pos_[b]) && !same(target, pos_[a])) std::swap(a, b);
  moved_[a] |= !same(target, pos_[a]);
  w.last_kept = a, w.last_removed = b;
  if (!absorbed_into_.empty()) absorbed_into_[b] = a;
  pos_[a] = target;
  quadric_[a] = q;
  boundary_[a] |= boundary_[b];
  ++w.vertices_removed;

  // Faces: those containing both ends degenerate and die; b's others now use a. Where the
  // topology check did not run (virtual pairs, or --no-preserve-topology), a face can land on the
  // same three vertices as one of a's: it dies too, so the output never has duplicate faces.
  aggregated_[a] |= aggregated_[b] | pairs_[p].is_virtual;
  const bool may_duplicate = aggregated_[a] || !opt_.preserve_topology;
  std::vector<std::uint32_t>& faces = w.scratch;
  faces.clear();
  for (std::uint32_t f : vertex_faces_[a]) {
    if (!face_alive_[f]) continue;
    if (face_has(f, b)) {
      kill_face(f, w);
      continue;
    }
    faces.push_back(f);
  }
  const std::size_t own = faces.size();
  for (std::uint32_t f : vertex_faces_[b]) {
    if (!face_alive_[f]) continue;
    std::uint32_t* t = &tri_[3 * std::size_t(f)];
    for (int k = 0; k < 3; ++k)
      if (t[k] == b) t[k] = a;
    if (may_duplicate && kill_if_coincident(f, own, w)) continue;
    faces.push_back(f);
  }
  if (may_duplicate) {  // drop the partners that cancelled
    std::size_t kept = 0;
    for (std::uint32_t f : faces)
      if (face_alive_[f]) faces[kept++] = f;
    faces.resize(kept);
  }
  if (!passes_) {  // in a pass, the lists wait for the next pass's rebuild (merged_from_)
    vertex_faces_.assign(a, faces.data(), faces.size(), b);
    vertex_faces_.clear(b);
  }

  // Pairs: GH97 §4 "pair sets merge": b's pairs now start at a; the contracted pair and any pair
  // that now duplicates another (same two vertices) are removed.
  pairs_[p].state = kDead;
  forget(p);
  const std::uint32_t s = ++w.stamp;
  mark_[a] = s;
  std::vector<std::uint32_t>& pairs = w.scratch2;
  pairs.clear();
  for (int end = 0; end < 2; ++end) {
    for (std::uint32_t r : vertex_pairs_[end == 0 ? a : b]) {
      if (pairs_[r].state == kDead) continue;
      std::uint32_t* v = pairs_[r].v;
      if (v[0] == b) v[0] = a;
      if (v[1] == b) v[1] = a;
      std::uint32_t o = v[0] == a ? v[1] : v[0];
      if (mark_[o] == s) {  // duplicate of a pair already kept (or a degenerate (a, a) pair)
        pairs_[r].state = kDead;
        forget(r);
        continue;
      }
      mark_[o] = s;
      if (v[0] > v[1]) std::swap(v[0], v[1]);
      pairs.push_back(r);
    }
  }
  if (passes_) {
    merged_from_[a] = b;
  } else {
    vertex_pairs_.assign(a, pairs.data(), pairs.size(), b);
    vertex_pairs_.clear(b);
  }

  // GH97 §4 step 5: update the costs of all valid pairs involving the new vertex.
  for (std::uint32_t r : pairs)
    if (pairs_[r].state != kLocked) cost_pair(r);
  unblock_around(a);
}

// Passes: the cost of every pair marked dirty, on all threads (each pair is independent, so the
// result does not depend on the thread count).
void Simplifier::recost_dirty_pairs() {
  const std::size_t np = pairs_.size();
  auto sweep = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t p = std::uint32_t(i);
      if (pairs_[p].state != kInHeap || !dirty_[p]) continue;
      dirty_[p] = 0;
      double c;
      if (pair_cost(p, c)) cost_[p] = float(c);
      else pairs_[p].state = kLocked;
    }
  };
  const std::size_t chunks = np < 65536 ? 1 : std::min<std::size_t>(thread_count(), 64);
  std::vector<std::thread> workers;
  for (std::size_t t = 1; t < chunks; ++t) workers.emplace_back(sweep, np * t / chunks, np * (t + 1) / chunks);
  sweep(0, np / chunks);
  for (std::thread& w : workers) w.join();
}

// Passes: once half the vertices are gone, the survivors, live faces and live pairs are numbered
// densely again, each in its old order, so later passes sweep small dense arrays instead of
// sparse ones (fewer cache misses per contraction). Every relative order is kept (tie-breaks on
// ids, the order of the rebuilt lists, output order), so the result is exactly the same. The
// vertex lists are rebuilt after it.
void Simplifier::renumber_densely() {
  // A vertex lives on while a live face or a pair that is not dead has it.
  // kNoVertex (gone), then 0 (used), then the new id; follow_contractions reads kNoVertex as gone.
  std::vector<std::uint32_t> vertex_to(pos_.size(), kNoVertex);
  for (std::uint32_t f = 0; f < face_alive_.size(); ++f)
    if (face_alive_[f])
      for (int k = 0; k < 3; ++k) vertex_to[tri_[3 * std::size_t(f) + k]] = 0;
  for (const PairRecord& r : pairs_)
    if (r.state != kDead) vertex_to[r.v[0]] = vertex_to[r.v[1]] = 0;
  std::uint32_t vertex_count = 0;
  for (std::uint32_t& to : vertex_to)
    if (to != kNoVertex) to = vertex_count++;

  // Pairs and faces keep their order, so each one's new id is the count of survivors before it
  // (nothing else refers to them: the vertex lists are rebuilt after this). Side by side.
  auto squeeze_pairs = [&] {
    std::size_t next = 0;
    for (std::size_t p = 0; p < pairs_.size(); ++p) {
      if (pairs_[p].state == kDead) continue;
      PairRecord r = pairs_[p];
      r.v[0] = vertex_to[r.v[0]], r.v[1] = vertex_to[r.v[1]];
      pairs_[next] = r, cost_[next] = cost_[p], dirty_[next] = dirty_[p];
      ++next;
    }
    pairs_.resize(next), cost_.resize(next), dirty_.resize(next);
  };
  auto squeeze_faces = [&] {
    std::size_t next = 0;
    for (std::size_t f = 0; f < face_alive_.size(); ++f) {
      if (!face_alive_[f]) continue;
      for (int k = 0; k < 3; ++k) tri_[3 * next + k] = vertex_to[tri_[3 * f + k]];
      face_source_[next++] = face_source_[f];
    }
    tri_.resize(3 * next), face_source_.resize(next);
    face_alive_.assign(next, 1);
  };
  side_by_side(squeeze_pairs, squeeze_faces);

  auto squeeze = [&](auto& array) {
    for (std::size_t i = 0; i < vertex_to.size(); ++i)
      if (vertex_to[i] != kNoVertex) array[vertex_to[i]] = array[i];
    array.resize(vertex_count);
  };
  squeeze(pos_);
  squeeze(quadric_);
  squeeze(boundary_);
  squeeze(moved_);
  squeeze(has_blocked_);
  squeeze(aggregated_);
  squeeze(source_vertex_);
  squeeze(touched_in_pass_);
  mark_.assign(vertex_count, 0);
  if (!home_.empty()) follow_contractions(vertex_to, vertex_count);
}

// The contraction map: each input vertex's home follows the contractions made since the last
// renumbering (path halving keeps the chains of a greedy run short), then takes its new id from
// `to` (kNoVertex: its vertex left the mesh).
void Simplifier::follow_contractions(const std::vector<std::uint32_t>& to, std::size_t vertex_count) {
  for (std::uint32_t& home : home_) {
    if (home == kNoVertex) continue;
    std::uint32_t v = home;
    while (absorbed_into_[v] != kNoVertex) {
      const std::uint32_t next = absorbed_into_[v];
      if (absorbed_into_[next] != kNoVertex) absorbed_into_[v] = absorbed_into_[next];
      v = next;
    }
    home = to[v];
  }
  absorbed_into_.assign(vertex_count, kNoVertex);
}

// ---------------------------------------------------------------------------------------------
// The order of contractions
// ---------------------------------------------------------------------------------------------

// Checks pair p against the topology, inversion and error limits and contracts it if it passes;
// otherwise it is blocked (retried when its neighbourhood changes) or, an edge whose faces all
// died, dropped.
bool Simplifier::try_contract(std::uint32_t p, Worker& w) {
  const std::uint32_t a = pairs_[p].v[0], b = pairs_[p].v[1];
  bool is_edge = false;
  if (!is_edge_and_link_ok(a, b, is_edge, w)) {
    ++w.blocked_topology;
    block(p);
    return false;
  }
  if (!is_edge && !pairs_[p].is_virtual) {
    // An edge pair whose faces all died: at t = 0 only edges are valid pairs (GH97 §3.2).
    pairs_[p].state = kDead;
    return false;
  }
  Quadric q;
  Placed placed;
  placement_for(p, q, placed);
  if (opt_.inversion == InversionPolicy::Forbid && flips(a, b, placed.position)) {
    ++w.blocked_inversion;
    block(p);
    return false;
  }
  double err = normalized_error(placed.error, q.weight);
  if (err > max_error_norm_) {
    ++w.blocked_error;
    block(p);
    return false;
  }
  w.max_error = std::max(w.max_error, err);
  contract(p, q, placed.position, w);
  ++w.contractions;
  if (opt_.record) record_contraction(err * scale_, w);
  return true;
}

// Moves a worker's counts into the run's totals (after each contraction on the calling thread,
// after each band for the others).
void Simplifier::absorb(Worker& w) {
  faces_alive_ -= w.faces_killed;
  vertices_alive_ -= w.vertices_removed;
  result_.contractions += w.contractions;
  blocked_by_topology_ += w.blocked_topology;
  blocked_by_inversion_ += w.blocked_inversion;
  blocked_by_error_ += w.blocked_error;
  max_error_norm_done_ = std::max(max_error_norm_done_, w.max_error);
  w.faces_killed = w.vertices_removed = w.contractions = 0;
  w.blocked_topology = w.blocked_inversion = w.blocked_error = 0;
}

// The contractions of a pass are known in advance, so the memory they will touch is requested a
// few contractions ahead, in stages (a pair's ends must be in cache before their data can be
// located): the loop then waits far less on memory. Always inlined, or GCC drops them (see
// core::VertexLists::prefetch_slot): 8-13 % of the run on the 1.3M sphere (docs/benchmarks.md).
[[gnu::always_inline]] inline void Simplifier::prefetch_for_contraction(const std::uint32_t* pairs,
                                                                        std::size_t count,
                                                                        std::size_t i) const {
  constexpr std::size_t kRecord = 12, kSlots = 8, kItems = 4, kNeighbours = 2;
  if (i + kRecord < count) __builtin_prefetch(&pairs_[pairs[i + kRecord]]);
  if (i + kSlots < count) {
    for (std::uint32_t v : pairs_[pairs[i + kSlots]].v) {
      vertex_faces_.prefetch_slot(v);
      vertex_pairs_.prefetch_slot(v);
      __builtin_prefetch(&pos_[v]);
      __builtin_prefetch(&quadric_[v]);
      __builtin_prefetch(reinterpret_cast<const char*>(&quadric_[v]) + 64);
    }
  }
  if (i + kItems < count) {
    for (std::uint32_t v : pairs_[pairs[i + kItems]].v) {
      vertex_faces_.prefetch_items(v);
      vertex_pairs_.prefetch_items(v);
    }
  }
  // Last, the records the checks and contract() read through those lists: the pairs and faces
  // around both ends (this stage: 3 % less time on the sphere to 10 %, none measurable to 1 %).
  if (i + kNeighbours < count) {
    for (std::uint32_t v : pairs_[pairs[i + kNeighbours]].v) {
      for (std::uint32_t r : vertex_pairs_[v]) __builtin_prefetch(&pairs_[r]);
      for (std::uint32_t f : vertex_faces_[v]) {
        __builtin_prefetch(&face_alive_[f]);
        __builtin_prefetch(&tri_[3 * std::size_t(f)]);
      }
    }
  }
}

// Calls the progress callback every few thousand contractions; false if the caller cancelled.
bool Simplifier::report_progress() {
  if (!opt_.progress || result_.contractions < next_progress_) return true;
  next_progress_ = result_.contractions + 4096;
  const std::size_t start = result_.input_faces;
  const std::size_t span = start > target_faces_ ? start - target_faces_ : 1;
  if (opt_.progress(double(start - faces_alive_) / double(span))) return true;
  result_.stop_reason = StopReason::Cancelled;
  return false;
}

// GH97 §4 steps 3-5: every pair in a heap keyed by its cost; repeatedly contract the cheapest.
void Simplifier::run_greedy() {
  heap_.reset(pairs_.size());
  cost_.assign(pairs_.size(), 0);
  for (std::uint32_t p = 0; p < pairs_.size(); ++p) {
    if (pairs_[p].state != kInHeap) continue;
    double c;
    if (pair_cost(p, c)) heap_.push_unordered(p, c), cost_[p] = float(c);
    else pairs_[p].state = kLocked;
  }
  heap_.heapify();

  while (!done()) {
    if (heap_.empty()) {
      result_.stop_reason = blocked_by_error_ > 0 ? StopReason::ErrorLimit : StopReason::NoValidPair;
      return;
    }
    if (!report_progress()) return;
    const std::uint32_t top = heap_.top();
    if (cost_[top] > heap_.top_key()) {  // stale key: re-key and look again
      heap_.update(top, cost_[top]);
      continue;
    }
    try_contract(heap_.pop(), main_);
    absorb(main_);
  }
}

// The pass-based order (the scheme of meshoptimizer's simplifier, with GH97's costs and checks).
// Each pass re-costs the pairs whose ends changed (one sweep in memory order, on all threads),
// sorts every candidate by cost (radix sort), and chooses, cheapest first, pairs whose two ends
// have not yet been chosen this pass, up to a quarter of the candidates and at most 1.5 times the
// cost at that quarter (the rule of meshoptimizer). No two chosen pairs share a vertex, so each
// one's cost is still exact when it is made, as in the greedy order; what differs is that the new
// vertex's own pairs wait for the next pass. The chosen pairs are made in memory order within
// bands of rising cost, which keeps the caches warm, and each band region by region on all
// threads (make_band).
void Simplifier::run_passes() {
  // Measured on the bunny, armadillo, igea and the 1.3M sphere (docs/benchmarks.md): a slack of
  // 1.2 or a share of 0.15 or 0.35 moved E by a few percent either way, case by case, with no
  // consistent gain. Fewer bands are faster (sparser sweeps cost cache misses: 2 bands save 15 %)
  // but worse: where two chosen pairs' checks interact, the cheaper should go first. On the sphere
  // to 1 %, E was 3.91e-8 with 2 bands, 3.84e-8 with 4, 3.71e-8 with 8 and 16.
  constexpr double kPassCostSlack = 1.5;
  constexpr double kPassShare = 0.25;
  constexpr std::size_t kBands = 8;
  cost_.assign(pairs_.size(), 0);
  dirty_.assign(pairs_.size(), 1);
  touched_in_pass_.assign(pos_.size(), 0);
  std::vector<std::uint32_t> order, scratch, selected;
  for (std::uint32_t pass = 1; !done(); ++pass) {
    if (pass > 1) {
      // The lists as the last pass left them (see merged_from_), rebuilt with live items only,
      // which also keeps each contraction's loops (and cache misses) to the live neighbourhood.
      if (2 * vertices_alive_ < pos_.size()) renumber_densely();
      side_by_side([&] { rebuild_pair_lists(); }, [&] { rebuild_face_lists(); });
    }
    merged_from_.assign(pos_.size(), kNoVertex);
    if (faces_alive_ <= opt_.greedy_below_faces) {
      passes_ = false;
      run_greedy();
      return;
    }
    recost_dirty_pairs();
    order.clear();
    order.reserve(pairs_.size());
    for (std::uint32_t p = 0; p < pairs_.size(); ++p)
      if (pairs_[p].state == kInHeap) order.push_back(p);
    if (order.empty()) {
      result_.stop_reason = blocked_by_error_ > 0 ? StopReason::ErrorLimit : StopReason::NoValidPair;
      return;
    }
    radix_sort_by_float_key(order, scratch, [&](std::uint32_t p) { return cost_[p]; });

    // This pass's share of the candidates, and the cost it may reach. Neither depends on the
    // target, so every target sees the same sequence of contractions, cut at a different point:
    // a contraction record replays to exactly the mesh a direct run to that size gives.
    const std::size_t share = std::max<std::size_t>(1, std::size_t(double(order.size()) * kPassShare));
    const double cost_goal = share < order.size() ? kPassCostSlack * cost_[order[share]] : kInf;

    // Choose this pass's contractions cheapest first, each vertex at most once...
    selected.clear();
    for (std::size_t i = 0; i < order.size(); ++i) {
      const std::uint32_t p = order[i];
      if (i + 16 < order.size()) __builtin_prefetch(&pairs_[order[i + 16]]);  // cost order: scattered
      if (selected.size() >= share) break;
      if (cost_[p] > cost_goal && selected.size() > share / 10) break;
      const std::uint32_t a = pairs_[p].v[0], b = pairs_[p].v[1];
      if (touched_in_pass_[a] == pass || touched_in_pass_[b] == pass) continue;
      touched_in_pass_[a] = touched_in_pass_[b] = pass;
      selected.push_back(p);
    }
    // ...then make them in kBands bands of rising cost, each band in memory order (pair ids
    // follow the Morton order of their ends), so the contractions walk the mesh's arrays instead
    // of jumping across them in cost order, and a run that reaches its target during a pass has
    // made the cheapest of the pass's contractions, spread over the whole mesh. No chosen pair
    // shares an end with another, so each one's cost is still exact when it is made; the
    // topology and inversion checks run on the mesh as it is at that moment (make_band says in
    // which order within a band).
    const std::size_t n = selected.size();
    for (std::size_t band = 0; band < kBands; ++band)
      std::sort(selected.begin() + n * band / kBands, selected.begin() + n * (band + 1) / kBands);
    find_region_cut();
    for (std::size_t band = 0; band < kBands && !done(); ++band) {
      const std::size_t begin = n * band / kBands, end = n * (band + 1) / kBands;
      if (!make_band(selected.data() + begin, end - begin)) return;
      if (check_invariants) check_lists();
    }
  }
}

// For the tests (core::check_invariants): every vertex's lists, as they are read, hold exactly its
// live faces and its pairs that are not dead. In a pass, a survivor's face list is never read
// again (it is not contracted twice), and a removed vertex's lists are not read at all; in the
// greedy order every list is kept exact.
void Simplifier::check_lists() const {
  const std::size_t n = pos_.size();
  std::vector<std::vector<std::uint32_t>> faces(n), pairs(n);
  for (std::uint32_t f = 0; f < face_alive_.size(); ++f)
    if (face_alive_[f])
      for (int k = 0; k < 3; ++k) faces[tri_[3 * std::size_t(f) + k]].push_back(f);
  for (std::uint32_t p = 0; p < pairs_.size(); ++p)
    if (pairs_[p].state != kDead) pairs[pairs_[p].v[0]].push_back(p), pairs[pairs_[p].v[1]].push_back(p);
  std::vector<std::uint8_t> removed(n, 0), survivor(n, 0);
  if (passes_)
    for (std::uint32_t v = 0; v < n; ++v)
      if (merged_from_[v] != kNoVertex) survivor[v] = 1, removed[merged_from_[v]] = 1;
  auto sorted = [](std::vector<std::uint32_t> items) {
    std::sort(items.begin(), items.end());
    return items;
  };
  for (std::uint32_t v = 0; v < n; ++v) {
    if (removed[v]) continue;
    std::vector<std::uint32_t> read;
    for_each_pair_of(v, [&](std::uint32_t p) {
      if (pairs_[p].state != kDead) read.push_back(p);
    });
    if (sorted(read) != pairs[v])
      throw std::logic_error("pair list out of step at vertex " + std::to_string(v));
    if (survivor[v]) continue;
    read.clear();
    for (std::uint32_t f : vertex_faces_[v])
      if (face_alive_[f]) read.push_back(f);
    if (sorted(read) != faces[v])
      throw std::logic_error("face list out of step at vertex " + std::to_string(v));
  }
}

// Whether pair p, chosen for this pass, is still to be made. With --inversion penalize its cost
// depends on the neighbours, which may have moved since it was ranked: then it waits.
bool Simplifier::ready_to_contract(std::uint32_t p) {
  if (pairs_[p].state != kInHeap) return false;
  if (opt_.inversion == InversionPolicy::Penalize) {
    double c;
    if (!pair_cost(p, c) || float(c) != cost_[p]) {
      dirty_[p] = 1;
      return false;
    }
  }
  return true;
}

// Marks the vertices that have a pair whose other end lies in another region (the ends of the
// pairs that cross a region border), and their neighbours. Called once a pass (the vertex ids
// change between passes); make_band keeps it up to date.
void Simplifier::find_region_cut() {
  region_scale_ = (std::uint64_t(kRegions) << 40) / std::max<std::size_t>(pos_.size(), 1);
  cut_.assign(pos_.size(), 0);
  near_cut_.assign(pos_.size(), 0);
  for (const PairRecord& r : pairs_)
    if (r.state != kDead && region_of(r.v[0]) != region_of(r.v[1])) mark_cut(r.v[0]), mark_cut(r.v[1]);
}

void Simplifier::mark_cut(std::uint32_t v) {
  if (cut_[v]) return;
  cut_[v] = near_cut_[v] = 1;
  mark_neighbours_near(v);
}

void Simplifier::mark_neighbours_near(std::uint32_t v) {
  for_each_pair_of(v, [&](std::uint32_t r) {
    if (pairs_[r].state != kDead) near_cut_[other_end(r, v)] = 1;
  });
}

// After a contraction in the border group, whose survivor took over the other end's pairs: a pair
// it now has into another region puts both ends on the cut, and the survivor's new neighbours
// next to the cut (or on it) are marked near it. (Contractions inside a region change neither.)
void Simplifier::update_cut_after(std::uint32_t a) {
  const std::uint32_t region = region_of(a);
  for_each_pair_of(a, [&](std::uint32_t r) {
    if (pairs_[r].state == kDead) return;
    const std::uint32_t o = other_end(r, a);
    if (region_of(o) != region) mark_cut(a), mark_cut(o);
    if (cut_[o]) near_cut_[a] = 1;
  });
  if (cut_[a]) mark_neighbours_near(a);
}

// Makes `count` chosen pairs (one band of a pass), in a fixed schedule that does not depend on the
// thread count: first, region by region, the pairs that lie inside a region, then the pairs near
// or across region borders, each group in the band's order. A pair is inside its region when
// neither end is on the cut or next to it. Everything its contraction reads or writes (the faces
// and pairs of its ends, their neighbours' flags and pairs) is then within two steps of its ends,
// so inside its region (the vertex lists are only read during a pass); and contractions inside a
// region never create a pair to another one, so this stays true through the band. So the regions
// can be made at the same time on several threads, with exactly the result of making them one
// after another. That is done unless the band could reach the target (the run must stop at
// exactly the same contraction) or the contractions are recorded; then they are made one after
// another, in the same schedule.
// Returns false if the caller cancelled.
bool Simplifier::make_band(const std::uint32_t* band, std::size_t count) {
  // Each pair to its region or to the border group.
  std::array<std::vector<std::uint32_t>, kRegions> inside;
  std::vector<std::uint32_t> border;
  std::size_t faces_at_stake = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t p = band[i], a = pairs_[p].v[0], b = pairs_[p].v[1];
    const std::uint32_t region = region_of(a);
    if (near_cut_[a] || near_cut_[b] || region_of(b) != region) {
      border.push_back(p);
      continue;
    }
    inside[region].push_back(p);
    faces_at_stake += vertex_faces_[a].size() + vertex_faces_[b].size();  // it removes only faces of its ends
  }
  // Disjoint stamp ranges (each contraction takes 3 stamps), so every stamp stays unique.
  std::array<std::uint32_t, kRegions> first_stamp;
  for (std::uint32_t r = 0; r < kRegions; ++r) {
    first_stamp[r] = main_.stamp;
    main_.stamp += std::uint32_t(3 * inside[r].size());
  }

  const std::size_t inside_count = count - border.size();
  const bool parallel = thread_count() > 1 && !opt_.record && faces_alive_ > target_faces_ + faces_at_stake &&
                        vertices_alive_ > target_vertices_ + inside_count;
  // Returns false if the caller cancelled.
  auto make_region = [&](std::uint32_t r, Worker& w, bool one_by_one) {
    w.stamp = first_stamp[r];
    const std::vector<std::uint32_t>& pairs = inside[r];
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      if (one_by_one && done()) break;
      if (one_by_one && !report_progress()) return false;
      prefetch_for_contraction(pairs.data(), pairs.size(), i);
      if (!ready_to_contract(pairs[i])) continue;
      try_contract(pairs[i], w);
      if (one_by_one) absorb(w);
    }
    return true;
  };

  bool go_on = true;
  if (parallel) {
    const unsigned threads = std::min<unsigned>(thread_count(), kRegions);
    std::vector<Worker> workers(threads);
    std::vector<std::exception_ptr> failures(threads);
    std::atomic<std::uint32_t> next_region{0};
    auto work = [&](unsigned t) {
      try {
        for (std::uint32_t r; (r = next_region.fetch_add(1)) < kRegions;) make_region(r, workers[t], false);
      } catch (...) {
        failures[t] = std::current_exception();
      }
    };
    std::vector<std::thread> helpers;
    try {
      for (unsigned t = 1; t < threads; ++t) helpers.emplace_back(work, t);
    } catch (const std::system_error&) {
      // No more threads to be had: this one takes the regions left (same result).
    }
    work(0);
    for (std::thread& h : helpers) h.join();
    for (unsigned t = 0; t < threads; ++t) {
      if (failures[t]) std::rethrow_exception(failures[t]);
      absorb(workers[t]);
    }
    go_on = report_progress();
  } else {
    const std::uint32_t stamp = main_.stamp;
    for (std::uint32_t r = 0; r < kRegions && go_on; ++r) go_on = make_region(r, main_, true);
    main_.stamp = stamp;
  }

  // The border group, one by one.
  for (std::size_t i = 0; i < border.size() && go_on; ++i) {
    if (done()) break;
    if (!report_progress()) return false;
    prefetch_for_contraction(border.data(), border.size(), i);
    if (!ready_to_contract(border[i]) || !try_contract(border[i], main_)) continue;
    absorb(main_);
    update_cut_after(main_.last_kept);
  }
  absorb(main_);
  return go_on;
}

// ---------------------------------------------------------------------------------------------

SimplifyResult Simplifier::run() {
  prepare_input();
  // The refit measures against the input's vertices weighted by area: taken before the faces go.
  if (opt_.refit_rounds > 0 && refit_weights) *refit_weights = refit_detail::vertex_areas(in_);
  // It starts its search for each input vertex's closest output face at the vertex that input
  // vertex was contracted into.
  if (opt_.refit_rounds > 0 && refit_map) {
    home_.assign(in_.vertex_count(), kNoVertex);
    for (std::uint32_t v = 0; v < source_vertex_.size(); ++v) home_[source_vertex_[v]] = v;
    absorbed_into_.assign(pos_.size(), kNoVertex);
  }
  if (consumed_indices) {
    in_.indices = {};
    std::vector<std::uint32_t>().swap(*consumed_indices);
  }
  resolve_targets();
  if (opt_.record) {
    *opt_.record = ContractionLog{};
    opt_.record->initial_faces = face_source_;
    std::sort(opt_.record->initial_faces.begin(), opt_.record->initial_faces.end());
  }

  if (done()) {
    result_.stop_reason = StopReason::AlreadyBelowTarget;
    result_.stop_detail = "the input already meets the target";
    return build_output();
  }
  rebuild_face_lists();
  // The quadrics and the edges are independent: found side by side.
  std::vector<Edge> edges;
  side_by_side([this] { compute_quadrics(); }, [&] { edges = unique_edges(tri_, vertex_faces_, pos_.size()); });
  select_pairs(std::move(edges));
  result_.virtual_pairs = virtual_pairs_;

  result_.stop_reason = StopReason::TargetReached;
  if (passes_) run_passes();
  else run_greedy();
  if (check_invariants) check_lists();
  if (opt_.progress && result_.stop_reason != StopReason::Cancelled) opt_.progress(1.0);

  result_.rejected_topology = blocked_by_topology_;
  result_.rejected_inversion = blocked_by_inversion_;
  result_.rejected_error = blocked_by_error_;
  result_.max_error_relative = max_error_norm_done_;
  result_.max_error = max_error_norm_done_ * scale_;
  switch (result_.stop_reason) {
    case StopReason::TargetReached: result_.stop_detail = "target reached"; break;
    case StopReason::ErrorLimit:
      result_.stop_detail = "every remaining contraction exceeds the error limit";
      break;
    case StopReason::NoValidPair:
      result_.stop_detail = "no valid contraction left (" + std::to_string(blocked_by_topology_) +
                            " rejected for topology, " + std::to_string(blocked_by_inversion_) +
                            " for face inversion" + (opt_.lock_border ? ", border locked" : "") + ")";
      break;
    default: result_.stop_detail = to_string(result_.stop_reason);
  }
  return build_output();
}

SimplifyResult Simplifier::build_output() {
  // Vertices no face uses any more are dropped; survivors and faces keep their input order.
  const std::uint32_t n = std::uint32_t(pos_.size());
  std::vector<std::uint8_t> used(n, 0);
  std::vector<std::uint32_t> faces;
  for (std::uint32_t f = 0; f < face_alive_.size(); ++f)
    if (face_alive_[f]) {
      faces.push_back(f);
      for (int k = 0; k < 3; ++k) used[tri_[3 * f + k]] = 1;
    }
  std::sort(faces.begin(), faces.end(), [&](std::uint32_t x, std::uint32_t y) { return face_source_[x] < face_source_[y]; });
  std::vector<std::uint32_t> survivors;
  for (std::uint32_t v = 0; v < n; ++v)
    if (used[v]) survivors.push_back(v);
  std::sort(survivors.begin(), survivors.end(),
            [&](std::uint32_t x, std::uint32_t y) { return source_vertex_[x] < source_vertex_[y]; });
  std::vector<std::uint32_t> remap(n, kNoVertex);  // kNoVertex: dropped
  Mesh& out = result_.mesh;
  out.positions.reserve(3 * survivors.size());
  for (std::uint32_t v : survivors) {
    remap[v] = std::uint32_t(out.positions.size() / 3);
    const Vec3 p = output_position(v);
    out.positions.insert(out.positions.end(), {p.x, p.y, p.z});
  }
  out.indices.reserve(3 * faces.size());
  for (std::uint32_t f : faces)
    for (int k = 0; k < 3; ++k) out.indices.push_back(remap[tri_[3 * f + k]]);
  if (!home_.empty()) {
    follow_contractions(remap, 0);
    *refit_map = std::move(home_);
  }
  return std::move(result_);
}

}  // namespace

RefitOptions refit_options(const SimplifyOptions& options) {
  RefitOptions r;
  r.rounds = options.refit_rounds;
  r.points_per_vertex = options.refit_points_per_vertex;
  r.lock_border = options.lock_border;
  r.max_normal_turn_degrees = options.max_normal_turn_degrees;
  r.threads = options.threads;
  return r;
}

namespace {

// Runs the simplifier, then the refit once the simplifier's arrays are freed.
SimplifyResult simplify_and_refit(MeshView input, const SimplifyOptions& options,
                                  std::vector<std::uint32_t>* consumed_indices) {
  std::vector<double> weights;
  std::vector<std::uint32_t> output_vertex;  // of each input vertex
  SimplifyResult out;
  {
    Simplifier s(input, options);
    s.consumed_indices = consumed_indices;
    s.refit_weights = &weights;
    s.refit_map = &output_vertex;
    out = s.run();
  }
  if (options.refit_rounds > 0 && out.contractions > 0 && out.stop_reason != StopReason::Cancelled) {
    const refit_detail::FitPoints points(input.positions, weights);
    const RefitResult fit =
        refit_detail::refit_to_points(points, out.mesh, refit_options(options), output_vertex);
    out.refit_rms_before = fit.rms_before;
    out.refit_rms_after = fit.rms_after;
    out.refit_rounds = fit.rounds;
  }
  return out;
}

}  // namespace

SimplifyResult simplify(MeshView input, const SimplifyOptions& options) {
  return simplify_and_refit(input, options, nullptr);
}

SimplifyResult simplify(Mesh&& input, const SimplifyOptions& options) {
  return simplify_and_refit(input, options, &input.indices);
}

}  // namespace qem
