#include "core/border_placement.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/collapse_checks.h"

namespace qem::core {

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
    if (e.faces > 2) m.corner[e.lo] = m.corner[e.hi] = 1;  // non-manifold: where sheets meet
    if (e.faces != 1) continue;
    add(e.lo, e.hi), add(e.hi, e.lo);
  }
  const double cos_corner = std::cos(kCornerDegrees * std::numbers::pi / 180);
  for (std::uint32_t v = 0; v < n; ++v) {
    if (count[v] == 0 || m.corner[v]) continue;
    if (count[v] != 2) {  // a border that ends, or two borders through one vertex
      m.corner[v] = 1;
      continue;
    }
    const Vec3 in = m.pos[v] - m.pos[other[2 * std::size_t(v)]], out = m.pos[other[2 * std::size_t(v) + 1]] - m.pos[v];
    const double scale = std::sqrt(dot(in, in) * dot(out, out));
    // The turn between the incoming and outgoing directions (0 on a straight border).
    if (!(dot(in, out) >= cos_corner * scale)) m.corner[v] = 1;
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
    ch.corner.push_back(m.corner[v] || m.held(v, false));
  }
  ch.neighbour.assign(2 * ch.pos.size(), kNoSlot);
  for (std::uint32_t v = 0; v < n; ++v)
    for (int k = 0; k < 2 && slot[v] != kNoSlot; ++k)
      if (other[2 * std::size_t(v) + k] != kNoVertex) ch.neighbour[2 * std::size_t(slot[v]) + k] = slot[other[2 * std::size_t(v) + k]];
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

// The input border from u to v along one direction: starting on edge x-y at parameter lo,
// toward y. False if a corner, a polyline's end or kMaxBorderWalk edges come first.
bool walk(const BorderChains& ch, std::uint32_t x, std::uint32_t y, double lo, const BorderSpot& v,
          std::vector<Piece>& out) {
  out.clear();
  for (std::size_t steps = 0; steps < kMaxBorderWalk && y != kNoSlot; ++steps) {
    const double tv = param_on(v, x, y);
    if (tv > lo) {
      out.push_back({x, y, lo, tv});
      return true;
    }
    out.push_back({x, y, lo, 1});
    if (v.to == kNoSlot && v.from == y) return true;
    if (ch.corner[y]) return false;  // a live vertex: v is not beyond it
    const std::uint32_t* nb = &ch.neighbour[2 * std::size_t(y)];
    const std::uint32_t next = nb[0] == x ? nb[1] : nb[0];
    x = y, y = next, lo = 0;
  }
  return false;
}

// The shorter of the two ways from u to v along the input border (empty: neither found).
std::vector<Piece> border_between(const BorderChains& ch, const BorderSpot& u, const BorderSpot& v) {
  std::vector<Piece> best, way;
  const auto consider = [&](std::uint32_t x, std::uint32_t y, double lo) {
    if (y == kNoSlot || !walk(ch, x, y, lo, v, way)) return;
    if (best.empty() || way.size() < best.size()) best = way;
  };
  if (u.to == kNoSlot) {
    consider(u.from, ch.neighbour[2 * std::size_t(u.from)], 0);
    consider(u.from, ch.neighbour[2 * std::size_t(u.from) + 1], 0);
  } else {
    consider(u.from, u.to, u.t);
    consider(u.to, u.from, 1 - u.t);
  }
  return best;
}

}  // namespace

void place_along_border(const Context& c, std::uint32_t a, std::uint32_t b, const Quadric& q, Placed& placed) {
  const WorkingMesh& m = c.mesh;
  const BorderChains& ch = m.chains;
  std::vector<Placed> cand;  // stable-sorted below: ties go to the earlier
  cand.push_back({m.pos[a], q.evaluate(m.pos[a]), m.border_spot[a]});
  cand.push_back({m.pos[b], q.evaluate(m.pos[b]), m.border_spot[b]});
  const BorderSpot& u = m.border_spot[a];
  const BorderSpot& v = m.border_spot[b];
  if (u.from != kNoSlot && v.from != kNoSlot) {
    const std::vector<Piece> pieces = border_between(ch, u, v);
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
      if ((i == 0 && s == p.lo) || (i + 1 == pieces.size() && s == p.hi)) continue;  // u or v: above
      BorderSpot spot{p.x, p.y, s};
      if (s == 0) spot = {p.x, kNoSlot, 0};
      if (s == 1) spot = {p.y, kNoSlot, 0};
      const Vec3 at = ch.at(spot);
      cand.push_back({at, q.evaluate(at), spot});
    }
  }
  std::stable_sort(cand.begin(), cand.end(),
                   [](const Placed& l, const Placed& r) { return l.error < r.error; });
  // The lowest error that keeps every face's side (GH97 §6); if none does, the lowest (refused).
  for (const Placed& k : cand)
    if (!flips(m, a, b, k.position, c.settings.cos_max_turn)) {
      placed = k;
      return;
    }
  placed = cand.front();
}

}  // namespace qem::core
