#include "core/border_placement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/collapse_checks.h"

namespace qem::core {

namespace {
double squared_distance_to_segment(const Vec3& p, const Vec3& s, const Vec3& e) {
  const Vec3 d = e - s, w = p - s;
  const double len2 = dot(d, d);
  const double t = len2 > 0 ? std::clamp(dot(w, d) / len2, 0.0, 1.0) : 0.0;
  const Vec3 r = w - d * t;
  return dot(r, r);
}
}  // namespace

void mark_border_corners(WorkingMesh& m, const std::vector<Edge>& edges) {
  const std::size_t n = m.vertex_count();
  m.corner.assign(n, 0);
  // Per vertex: its border edges (up to two other ends kept) and whether it has more.
  std::vector<std::uint8_t> count(n, 0);
  std::vector<std::uint32_t> other(2 * n, kNoVertex);
  const auto add = [&](std::uint32_t v, std::uint32_t o) {
    if (count[v] < 2) other[2 * std::size_t(v) + count[v]] = o;
    if (count[v] < 255) ++count[v];
  };
  for (const Edge& e : edges) {
    if (e.faces > 2) m.corner[e.lo] = m.corner[e.hi] = kHardCorner;  // non-manifold: where sheets meet
    if (e.faces != 1) continue;
    add(e.lo, e.hi), add(e.hi, e.lo);
  }
  const double cos_corner = std::cos(kCornerDegrees * std::numbers::pi / 180);
  for (std::uint32_t v = 0; v < n; ++v) {
    if (count[v] == 0 || m.corner[v]) continue;
    if (count[v] != 2) {  // a border that ends, or two borders through one vertex
      m.corner[v] = kHardCorner;
      continue;
    }
    const Vec3 in = m.pos[v] - m.pos[other[2 * std::size_t(v)]], out = m.pos[other[2 * std::size_t(v) + 1]] - m.pos[v];
    const double scale = std::sqrt(dot(in, in) * dot(out, out));
    // The turn between the incoming and outgoing directions (0 on a straight border).
    if (!(dot(in, out) >= cos_corner * scale)) m.corner[v] = kSoftCorner;
  }
  // The polylines: one slot per border vertex, in vertex order.
  BorderChains& ch = m.chains;
  ch = BorderChains{};
  m.border_spot.assign(n, BorderSpot{});
  std::vector<std::uint32_t> slot(n, kNoSlot);
  for (std::uint32_t v = 0; v < n; ++v) {
    if (count[v] == 0) continue;
    slot[v] = std::uint32_t(ch.pos.size());
    m.border_spot[v].from = slot[v];
    ch.pos.push_back(m.pos[v]);
    ch.corner.push_back(m.corner[v] != 0 || m.held(v, false));
  }
  ch.neighbour.assign(2 * ch.pos.size(), kNoSlot);
  for (std::uint32_t v = 0; v < n; ++v)
    for (int k = 0; k < 2 && slot[v] != kNoSlot; ++k)
      if (other[2 * std::size_t(v) + k] != kNoVertex) ch.neighbour[2 * std::size_t(slot[v]) + k] = slot[other[2 * std::size_t(v) + k]];
  // Each soft corner's size: its distance from the line between the nearest corners (or held
  // vertices) on either side along the input border, at most kCornerWalk edges away; on a loop
  // with no other corner, its distance to the farthest slot. Scan noise is a corner between
  // corners close by (a small size); a square's corner sits between the square's other corners.
  ch.corner_size.assign(ch.pos.size(), 0);
  for (std::uint32_t v = 0; v < n; ++v) {
    if (slot[v] == kNoSlot || m.corner[v] != kSoftCorner) continue;
    const std::uint32_t s0 = slot[v];
    std::uint32_t end[2] = {kNoSlot, kNoSlot};
    double farthest = 0;
    bool around = false;
    for (int side = 0; side < 2 && !around; ++side) {
      std::uint32_t prev = s0, cur = ch.neighbour[2 * std::size_t(s0) + side];
      for (std::size_t steps = 0; cur != kNoSlot && cur != s0; ++steps) {
        farthest = std::max(farthest, std::sqrt(dot(ch.pos[cur] - ch.pos[s0], ch.pos[cur] - ch.pos[s0])));
        end[side] = cur;
        if (ch.corner[cur] || steps == kCornerWalk) break;
        const std::uint32_t* nb = &ch.neighbour[2 * std::size_t(cur)];
        const std::uint32_t next = nb[0] == prev ? nb[1] : nb[0];
        prev = cur, cur = next;
      }
      around = cur == s0;
    }
    ch.corner_size[s0] = around || end[0] == kNoSlot || end[1] == kNoSlot
                             ? farthest
                             : std::sqrt(squared_distance_to_segment(ch.pos[s0], ch.pos[end[0]], ch.pos[end[1]]));
  }
  // Each simple closed loop's size (its slots all on two border edges, none a hard corner).
  const std::size_t slots = ch.pos.size();
  ch.loop_radius.assign(slots, std::numeric_limits<double>::infinity());
  std::vector<std::uint8_t> simple(slots, 0), seen(slots, 0);
  for (std::uint32_t v = 0; v < n; ++v)
    if (slot[v] != kNoSlot) simple[slot[v]] = count[v] == 2 && m.corner[v] != kHardCorner && !m.held(v, false);
  std::vector<std::uint32_t> loop;
  for (std::uint32_t s0 = 0; s0 < slots; ++s0) {
    if (seen[s0]) continue;
    loop.clear();
    bool closed = false;
    for (std::uint32_t prev = kNoSlot, cur = s0; cur != kNoSlot && !seen[cur];) {
      seen[cur] = 1;
      loop.push_back(cur);
      const std::uint32_t* nb = &ch.neighbour[2 * std::size_t(cur)];
      const std::uint32_t next = nb[0] != prev ? nb[0] : nb[1];
      prev = cur, cur = next;
      closed = cur == s0;
    }
    if (!closed || loop.size() < 3) continue;
    if (!std::all_of(loop.begin(), loop.end(), [&](std::uint32_t x) { return simple[x] != 0; })) continue;
    Vec3 lo = ch.pos[loop[0]], hi = lo;
    for (std::uint32_t x : loop) {
      const Vec3& p = ch.pos[x];
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    const double radius = 0.5 * std::sqrt(dot(hi - lo, hi - lo));
    for (std::uint32_t x : loop) ch.loop_radius[x] = radius;
  }
}

namespace {

// The part [lo, hi] of input border edge x-y (parameters from x).
struct Piece {
  std::uint32_t x, y;
  double lo, hi;
};

// Where v lies on input edge x-y, as a parameter from x; negative if not on it (or at its ends).
double param_on(const BorderSpot& v, std::uint32_t x, std::uint32_t y) {
  if (v.to == kNoSlot) return -1;
  if (v.from == x && v.to == y) return v.t;
  if (v.from == y && v.to == x) return 1 - v.t;
  return -1;
}

// One way along the input border toward v, a step (an input edge) at a time: starting on edge x-y
// at parameter lo, toward y. It ends found, or dead at a corner (unless `through_corners`) or a
// polyline's end.
struct BorderWalk {
  std::uint32_t x, y;
  double lo;
  std::vector<Piece>& pieces;  // emptied: the caller's, so that its capacity is kept from walk to walk
  enum { Going, Found, Dead } state = Going;

  BorderWalk(std::uint32_t from, std::uint32_t to, double at, std::vector<Piece>& out)
      : x(from), y(to), lo(at), pieces(out) {
    pieces.clear();
    if (y == kNoSlot) state = Dead;
  }
  void step(const BorderChains& ch, const BorderSpot& v, bool through_corners) {
    const double tv = param_on(v, x, y);
    if (tv > lo) {
      pieces.push_back({x, y, lo, tv});
      state = Found;
      return;
    }
    pieces.push_back({x, y, lo, 1});
    if (v.to == kNoSlot && v.from == y) {
      state = Found;
      return;
    }
    if (ch.corner[y] && !through_corners) {  // a live vertex: v is not beyond it
      state = Dead;
      return;
    }
    const std::uint32_t* nb = &ch.neighbour[2 * std::size_t(y)];
    const std::uint32_t next = nb[0] == x ? nb[1] : nb[0];
    x = y, y = next, lo = 0;
    if (y == kNoSlot) state = Dead;
  }
};

// Whether piece p reaches spot v past its start (a way starts at u, not at v).
bool piece_reaches(const Piece& p, const BorderSpot& v) {
  if (v.to == kNoSlot) return v.from == p.y && p.hi == 1;
  const double tv = param_on(v, p.x, p.y);
  return tv > p.lo && tv <= p.hi;
}

// The shorter of the two ways from u to v along the input border (empty: neither found within
// kMaxBorderWalk edges; of two as short, the first), valid until the thread's next call. A corner
// ends a way unless `through_corners` (a soft corner the run removed still has its slot). The two
// ways are walked in step, so a contraction near one end of a long border (a terrain's side)
// never walks the wrong way round.
//
// With `avoid`, only a way that does not pass that spot before v (at v's own place either way is
// as good), for chord_error: u is a current border neighbour of a moving end, v that end's new
// place, and `avoid` u's other current border neighbour's place, which the way u leaves toward v
// does not pass. The shorter way is not always that one: where the current border has few
// vertices left (a zero-width slit, whose removed side is many input edges long while the way
// back round the loop is few), the shorter way runs through the part of the border that stays
// and misses the part the contraction removes (the dragon at 10 %: a slit's bend 1.8e-4 from the
// output).
const std::vector<Piece>& border_between(const BorderChains& ch, const BorderSpot& u, const BorderSpot& v,
                                         bool through_corners = false, const BorderSpot* avoid = nullptr) {
  // The two ways' pieces, per thread (the placements run on the re-costing threads): the answer
  // is read before the next call, and no call allocates once they have grown.
  thread_local std::vector<Piece> found[2];
  static const std::vector<Piece> none;
  BorderWalk ways[2] = {
      u.to == kNoSlot ? BorderWalk(u.from, ch.neighbour[2 * std::size_t(u.from)], 0, found[0])
                      : BorderWalk(u.from, u.to, u.t, found[0]),
      u.to == kNoSlot ? BorderWalk(u.from, ch.neighbour[2 * std::size_t(u.from) + 1], 0, found[1])
                      : BorderWalk(u.to, u.from, 1 - u.t, found[1])};
  for (std::size_t steps = 0; steps < kMaxBorderWalk; ++steps) {
    bool going = false;
    for (BorderWalk& w : ways) {
      if (w.state != BorderWalk::Going) continue;
      w.step(ch, v, through_corners);
      if (avoid && piece_reaches(w.pieces.back(), *avoid)) {
        const Piece& last = w.pieces.back();
        const double ts = avoid->to == kNoSlot ? 1 : param_on(*avoid, last.x, last.y);
        if (ts < last.hi || w.state != BorderWalk::Found) {
          w.state = BorderWalk::Dead;
          continue;
        }
      }
      if (w.state == BorderWalk::Found) return w.pieces;
      going |= w.state == BorderWalk::Going;
    }
    if (!going) break;
  }
  return none;
}

// Up to two neighbours of v along the current border other than `not_this`, in the order of v's
// faces and their corners; kNoVertex for none. A neighbour is on the border with v when exactly one
// live face of v's list has it (border_detail::is_border_edge): below the hub's size the faces are
// counted from v's list, so one walk over it counts every neighbour at once (the test per
// neighbour walked the list again for each). A hub's neighbours are tested one by one, as
// is_border_edge counts them from the other end.
void border_neighbours(const WorkingMesh& m, std::uint32_t v, std::uint32_t not_this, std::uint32_t out[2]) {
  out[0] = out[1] = kNoVertex;
  const auto faces = m.vertex_faces[v];
  if (faces.size() > border_detail::kHubFaces) {
    for (std::uint32_t f : faces) {
      if (!m.face_alive[f]) continue;
      const std::uint32_t* t = m.face(f);
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t n = t[k];
        if (n == v || n == not_this || n == out[0] || n == out[1] || !border_detail::is_border_edge(m, v, n))
          continue;
        if (out[0] == kNoVertex)
          out[0] = n;
        else
          out[1] = n;
        if (out[1] != kNoVertex) return;
      }
    }
    return;
  }
  // Each other corner once, in order of first appearance, with the number of faces it is on.
  std::uint32_t corner[2 * border_detail::kHubFaces];
  std::uint32_t count[2 * border_detail::kHubFaces];
  std::size_t corners = 0;
  for (std::uint32_t f : faces) {
    if (!m.face_alive[f]) continue;
    const std::uint32_t* t = m.face(f);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t n = t[k];
      if (n == v || (k > 0 && n == t[0]) || (k > 1 && n == t[1])) continue;  // each corner of a face once
      std::size_t i = 0;
      while (i < corners && corner[i] != n) ++i;
      if (i == corners) corner[corners] = n, count[corners++] = 0;
      ++count[i];
    }
  }
  for (std::size_t i = 0; i < corners; ++i) {
    if (count[i] != 1 || corner[i] == not_this) continue;
    if (out[0] == kNoVertex)
      out[0] = corner[i];
    else {
      out[1] = corner[i];
      return;
    }
  }
}

// v's neighbour along the current border other than `not_this` (kNoVertex if none).
std::uint32_t other_border_neighbour(const WorkingMesh& m, std::uint32_t v, std::uint32_t not_this) {
  std::uint32_t out[2];
  border_neighbours(m, v, not_this, out);
  return out[0];
}

}  // namespace

double corner_error(const Context& c_, std::uint32_t a, std::uint32_t b, const Vec3& x, double weight) {
  const WorkingMesh& m = c_.mesh;
  if (m.corner.empty()) return 0;
  const auto same = [](const Vec3& p, const Vec3& q) { return p.x == q.x && p.y == q.y && p.z == q.z; };
  double size = 0;
  for (int end = 0; end < 2; ++end) {
    const std::uint32_t e = end == 0 ? a : b;
    // A soft corner never moved, so it is at its own slot.
    if (m.corner[e] == kSoftCorner && !same(x, m.pos[e]) && m.border_spot[e].from != kNoSlot)
      size = std::max(size, m.chains.corner_size[m.border_spot[e].from]);
  }
  return (weight > 0 ? weight : 1) * size * size;
}

void ChordError::find_neighbours() {
  const WorkingMesh& m = c_.mesh;
  found_ = true;
  border_neighbours(m, a_, b_, nbr_[0]);
  border_neighbours(m, b_, a_, nbr_[1]);
  // A hole down to three vertices: the contraction closes it (hole_error), no border edge is left.
  closes_hole_ = nbr_[0][0] != kNoVertex && (nbr_[0][0] == nbr_[1][0] || nbr_[0][0] == nbr_[1][1]);
  for (int end = 0; end < 2; ++end)
    for (int k = 0; k < 2; ++k) {
      const std::uint32_t n = nbr_[end][k];
      if (n == kNoVertex || m.border_spot[n].from == kNoSlot) continue;
      // Through corners: a soft corner between n and x is gone if the way reaches x (a live one
      // would be a vertex of the current border between them, which n and x are neighbours on).
      // The way toward the end, not the one past n's other neighbour (border_between's `avoid`),
      // where n is on a simple chain: one other border neighbour, no hard corner (where borders
      // meet, the shorter way as before).
      std::uint32_t beyond[2];
      border_neighbours(m, n, end == 0 ? a_ : b_, beyond);
      const bool simple = m.corner[n] != kHardCorner && beyond[0] != kNoVertex && beyond[1] == kNoVertex &&
                          m.border_spot[beyond[0]].from != kNoSlot;
      avoid_[end][k] = simple ? &m.border_spot[beyond[0]] : nullptr;
    }
}

double ChordError::operator()(const Vec3& x, const BorderSpot& xs) {
  const WorkingMesh& m = c_.mesh;
  const std::uint32_t a = a_, b = b_;
  if (!c_.settings.exact_border || m.corner.empty() || xs.from == kNoSlot || !(m.boundary[a] || m.boundary[b])) return 0;
  const auto same = [](const Vec3& p, const Vec3& q) { return p.x == q.x && p.y == q.y && p.z == q.z; };
  // No border end moves (a held or locked end, such as a part's cut): no border edge changes.
  if (!(m.boundary[a] && !same(x, m.pos[a])) && !(m.boundary[b] && !same(x, m.pos[b]))) return 0;
  if (!found_) find_neighbours();
  if (closes_hole_) return 0;
  double d2 = 0;
  for (int end = 0; end < 2; ++end) {
    const std::uint32_t e = end == 0 ? a : b;
    if (!m.boundary[e] || same(x, m.pos[e])) continue;  // e stays: its border edges are as they were
    for (int k = 0; k < 2; ++k) {
      const std::uint32_t n = nbr_[end][k];
      if (n == kNoVertex || m.border_spot[n].from == kNoSlot) continue;
      const Vec3& s = m.pos[n];
      const std::vector<Piece>& way = border_between(m.chains, m.border_spot[n], xs, true, avoid_[end][k]);
      for (const Piece& p : way) {
        const Vec3 o = m.chains.pos[p.x], d = m.chains.pos[p.y] - o;
        d2 = std::max({d2, squared_distance_to_segment(o + d * p.lo, s, x), squared_distance_to_segment(o + d * p.hi, s, x)});
      }
    }
  }
  return (weight_ > 0 ? weight_ : 1) * d2;
}

double chord_error(const Context& c, std::uint32_t a, std::uint32_t b, const Vec3& x, const BorderSpot& xs,
                   double weight) {
  return ChordError(c, a, b, weight)(x, xs);
}

std::uint32_t hole_closed_by(const WorkingMesh& m, std::uint32_t a, std::uint32_t b) {
  if (m.corner.empty() || !m.boundary[a] || !m.boundary[b] || !border_detail::is_border_edge(m, a, b)) return kNoVertex;
  const std::uint32_t ca = other_border_neighbour(m, a, b);
  if (ca == kNoVertex || ca != other_border_neighbour(m, b, a)) return kNoVertex;
  // c must not be the third corner of the face on (a, b): then the loop is that face's own border.
  for (std::uint32_t f : m.vertex_faces[a])
    if (m.face_alive[f] && m.face_has(f, b) && m.face_has(f, ca)) return kNoVertex;
  // Only the hole of an input loop that is simple and closed has a size (BorderChains::loop_radius).
  const std::uint32_t slot = m.border_spot[a].from;
  if (slot == kNoSlot || !std::isfinite(m.chains.loop_radius[slot])) return kNoVertex;
  return ca;
}

double hole_error(const WorkingMesh& m, std::uint32_t a, std::uint32_t b, double weight) {
  if (hole_closed_by(m, a, b) == kNoVertex) return 0;  // not a hole that may close (the link condition refuses it)
  const double r = m.chains.loop_radius[m.border_spot[a].from];
  return (weight > 0 ? weight : 1) * r * r;
}

void update_border_after_closing(WorkingMesh& m, std::uint32_t v) {
  bool on_border = false;
  for (std::uint32_t f : m.vertex_faces[v]) {
    if (!m.face_alive[f]) continue;
    const std::uint32_t* t = m.face(f);
    for (int k = 0; k < 3 && !on_border; ++k)
      on_border = t[k] != v && border_detail::is_border_edge(m, v, t[k]);
    if (on_border) break;
  }
  if (on_border) return;
  m.boundary[v] = 0;  // interior now: free to move (its border planes still rank it)
  if (m.corner[v] == kSoftCorner) m.corner[v] = 0;
  m.border_spot[v] = BorderSpot{};
}

namespace {

// Appends, for each piece of input border (the way from u to v, border_between), the minimiser of
// q along it (GH97 §4's segment placement) unless it is the way's start or end (u's and v's own
// places, which the caller handles).
template <class ErrorAt>
void add_piece_minima(const BorderChains& ch, const std::vector<Piece>& pieces, const Quadric& q, const ErrorAt& error_at,
                      std::vector<Placed>& cand) {
  const double trace = q.a00 + q.a11 + q.a22;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const Piece& p = pieces[i];
    // Q along the edge, x + s d: Q(x) + 2 s (A x + b).d + s^2 d^T A d (as place_on_segment).
    const Vec3 x = ch.pos[p.x], d = ch.pos[p.y] - x;
    const double curvature = dot(d, q.apply_a(d));
    double s;
    if (curvature > 1e-12 * trace * dot(d, d)) {
      const Vec3 g = q.apply_a(x) + Vec3(q.b0, q.b1, q.b2);
      s = std::clamp(-dot(g, d) / curvature, p.lo, p.hi);
    } else {
      s = q.evaluate(x + d * p.lo) <= q.evaluate(x + d * p.hi) ? p.lo : p.hi;
    }
    if ((i == 0 && s == p.lo) || (i + 1 == pieces.size() && s == p.hi)) continue;  // u or v: the caller's
    BorderSpot spot{p.x, p.y, s};
    if (s == 0) spot = {p.x, kNoSlot, 0};
    if (s == 1) spot = {p.y, kNoSlot, 0};
    const Vec3 at = ch.at(spot);
    cand.push_back({at, error_at(at), spot});
  }
}

// The lowest-error candidate, its chord (chord_error) included, that keeps every face's side
// (GH97 §6); if none does, the lowest (refused later). Ties go to the earlier in `cand`.
// A chord only adds to a candidate's own error, so the candidates are priced in the order of
// their own errors, and one whose priced error is below every unpriced one's own comes before all
// of those: it is tested then, and most contractions price one or two of their candidates instead
// of all (a terrain's slides along long borders have many). The same choice, and the same flip
// tests, as pricing all and then testing them in order.
void choose(const Context& c, std::uint32_t a, std::uint32_t b, std::vector<Placed>& cand, ChordError* chord,
            Placed& placed) {
  const std::size_t n = cand.size();
  std::vector<std::uint32_t> by_own(n);
  for (std::uint32_t i = 0; i < n; ++i) by_own[i] = i;
  std::stable_sort(by_own.begin(), by_own.end(),
                   [&](std::uint32_t l, std::uint32_t r) { return cand[l].error < cand[r].error; });
  std::vector<std::uint32_t> priced;  // not yet tested
  const Placed* least = nullptr;      // the first in the order: the choice if every one flips
  for (std::size_t next = 0;;) {
    // Out come the priced ones below every unpriced one (all of them once every one is priced).
    for (;;) {
      const auto it = std::min_element(priced.begin(), priced.end(), [&](std::uint32_t l, std::uint32_t r) {
        return cand[l].error < cand[r].error || (cand[l].error == cand[r].error && l < r);
      });
      if (it == priced.end() || (next < n && !(cand[*it].error < cand[by_own[next]].error))) break;
      const Placed& k = cand[*it];
      priced.erase(it);
      if (!least) least = &k;
      if (!flips(c.mesh, a, b, k.position, c.settings.cos_max_turn)) {
        placed = k;
        return;
      }
    }
    if (next == n) break;
    Placed& k = cand[by_own[next]];
    if (chord) k.error = std::max(k.error, (*chord)(k.position, k.spot));
    priced.push_back(by_own[next++]);
  }
  placed = *least;
}

}  // namespace

void place_along_border(const Context& c, std::uint32_t a, std::uint32_t b, const Quadric& q, Placed& placed) {
  const WorkingMesh& m = c.mesh;
  std::vector<Placed> cand;
  // Each candidate's error: Q there, or a soft corner's size if it removes one (corner_error).
  const auto error_at = [&](const Vec3& x) { return std::max(q.evaluate(x), corner_error(c, a, b, x, q.weight)); };
  cand.push_back({m.pos[a], error_at(m.pos[a]), m.border_spot[a]});
  cand.push_back({m.pos[b], error_at(m.pos[b]), m.border_spot[b]});
  const BorderSpot& u = m.border_spot[a];
  const BorderSpot& v = m.border_spot[b];
  if (u.from != kNoSlot && v.from != kNoSlot) add_piece_minima(m.chains, border_between(m.chains, u, v), q, error_at, cand);
  ChordError chord(c, a, b, q.weight);
  choose(c, a, b, cand, &chord, placed);
}

void place_on_own_border(const Context& c, std::uint32_t a, std::uint32_t b, const Quadric& q, Placed& placed) {
  const WorkingMesh& m = c.mesh;
  std::vector<Placed> cand;
  cand.push_back({m.pos[a], q.evaluate(m.pos[a]), m.border_spot[a]});
  // Each slide is tested against every face around a and b (choose); around a fan's hub (a
  // triangulated n-gon: any number of faces) that test, on every re-cost of the hub's pairs,
  // would make the run quadratic in the hub's valence, so there a stays, as a held end does.
  constexpr std::size_t kMaxSlideFaces = 64;
  if (m.vertex_faces[a].size() + m.vertex_faces[b].size() > kMaxSlideFaces) {
    placed = cand.front();  // checked for flips when it is made, as any placement
    return;
  }
  const BorderSpot& u = m.border_spot[a];
  if (u.from != kNoSlot && !(u.to == kNoSlot && m.chains.corner[u.from])) {
    const auto error_at = [&](const Vec3& x) { return q.evaluate(x); };
    // a's two neighbours along the current border; it may slide toward either, short of it.
    const std::uint32_t n0 = other_border_neighbour(m, a, kNoVertex);
    const std::uint32_t n1 = n0 == kNoVertex ? kNoVertex : other_border_neighbour(m, a, n0);
    for (std::uint32_t n : {n0, n1})
      if (n != kNoVertex && m.border_spot[n].from != kNoSlot)
        add_piece_minima(m.chains, border_between(m.chains, u, m.border_spot[n]), q, error_at, cand);
    // A slide moves a's two border edges (a's own place, cand[0], moves none).
    ChordError chord(c, a, b, q.weight);
    choose(c, a, b, cand, &chord, placed);
    return;
  }
  choose(c, a, b, cand, nullptr, placed);
}

}  // namespace qem::core
