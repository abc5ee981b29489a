// The cost of contracting a pair and where its new vertex goes (GH97 §4): Q = Q_a + Q_b,
// placed by the chosen policy, cost Q(position), honouring --lock-border and --inversion penalize.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "core/border_placement.h"
#include "core/collapse_checks.h"
#include "core/context.h"
#include "core/placement.h"

namespace qem::core {

/// Heap and ranking keys are floats (24 significant bits). The same model scaled or moved gives
/// costs that differ only by rounding noise (~1e-16 relative); rounded to float they tie, ties
/// break on the pair id, and the contraction order (and so the output) does not depend on the
/// model's scale or position. It also halves the memory the orders sort and sift.
inline double round_key(double cost) { return double(float(cost)); }

/// A quadric error as a distance: sqrt(Q / total plane weight), the weighted RMS distance to the
/// planes it stands for.
inline double normalized_error(double q_error, double weight) {
  return weight > 0 ? std::sqrt(q_error / weight) : std::sqrt(q_error);
}

/// With attributes: the placement of the collapse of (a, b) over the positional quadric q plus the
/// reduced attribute quadrics of the wedges it merges (Hoppe 1999; Hoppe & Marschner 2000's reduced
/// solve, through place()). A seam or material boundary stays where it is: when either end has
/// more than one wedge, the survivor stays at its own position, and the removed end's wedges must
/// each meet one of the survivor's on the edge's faces (the collapse runs along the seam, both
/// sides together; map_wedges, wedges.h). False if neither direction is allowed.
bool place_with_wedges(const Context& c, std::uint32_t a, std::uint32_t b, const Quadric& q, Placed& placed);

/// The quadric and placement of pair p. False if the pair cannot be placed now (both ends on a
/// locked border, two hard corners or two stretches of border under exact borders, or, with
/// attributes, a collapse that would move or close a seam; refused_state says whether that lasts);
/// with one end on a locked border, that end is the
/// placement; under exact borders, border_target decides (border_placement.h).
inline bool place_pair(const Context& c, std::uint32_t p, Quadric& q, Placed& placed) {
  const std::uint32_t a = c.pairs.pairs[p].v[0], b = c.pairs.pairs[p].v[1];
  const WorkingMesh& m = c.mesh;
  q = c.quadric[a] + c.quadric[b];
  // Most pairs: neither end on a border, a corner or locked, no attributes. Every rule below then
  // comes to the plain placement; deciding it from the flags at once saves the roles' lookups on
  // every pair cost.
  if (!c.wedges && !m.boundary[a] && !m.boundary[b] && (m.corner.empty() || (m.corner[a] | m.corner[b]) == 0) &&
      (m.locked.empty() || (m.locked[a] | m.locked[b]) == 0)) {
    placed = place(q, m.pos[a], m.pos[b], c.settings.placement);
    return true;
  }
  const BorderTarget border = border_target(c, a, b);
  if (c.wedges) {
    if (!place_with_wedges(c, a, b, q, placed)) return false;
    if (border == BorderTarget::AtEither) placed.error = std::max(placed.error, hole_error(m, a, b, q.weight));
    return true;
  }
  switch (border) {
    case BorderTarget::Free: break;
    case BorderTarget::Never: return false;
    case BorderTarget::AtA:  // the other end may be a soft corner that leaves (corner_error)
    case BorderTarget::AtB: {
      const bool at_a = border == BorderTarget::AtA;
      const std::uint32_t keep = at_a ? a : b, other = at_a ? b : a;
      if (border_detail::role(c, keep) == border_detail::Role::Border && !m.boundary[other])
        place_on_own_border(c, keep, other, q, placed);  // keep slides along its border
      else
        placed = {m.pos[keep], std::max({q.evaluate(m.pos[keep]), corner_error(c, a, b, m.pos[keep], q.weight),
                                         chord_error(c, a, b, m.pos[keep], m.border_spot[keep], q.weight)})};
      return true;
    }
    case BorderTarget::AtEither:
      place_along_border(c, a, b, q, placed);
      placed.error = std::max(placed.error, hole_error(m, a, b, q.weight));  // a hole down to three vertices
      return true;
  }
  const bool held_a = m.held(a, c.settings.lock_border), held_b = m.held(b, c.settings.lock_border);
  if (held_a || held_b) {
    if (held_a && held_b) return false;
    const Vec3& fixed = held_a ? m.pos[a] : m.pos[b];
    placed = {fixed, q.evaluate(fixed)};
    return true;
  }
  placed = place(q, m.pos[a], m.pos[b], c.settings.placement);
  return true;
}

/// Whether pair p can never be contracted, whatever happens around it: both ends held (a locked
/// border, vertex_lock) or, under exact borders, both hard corners. place_pair's other refusals
/// last only as long as the neighbourhood that causes them: a collapse that would move or close a
/// seam is allowed once the faces on one side of the seam are gone (Wedges::drop_unused), and two
/// border vertices joined by an interior edge share a border edge once the vertex between them is
/// gone. Those pairs are blocked (retried when their neighbourhood changes), not locked.
inline bool never_contracts(const Context& c, std::uint32_t p) {
  using border_detail::Role;
  const std::uint32_t a = c.pairs.pairs[p].v[0], b = c.pairs.pairs[p].v[1];
  const WorkingMesh& m = c.mesh;
  if (m.held(a, c.settings.lock_border) && m.held(b, c.settings.lock_border)) return true;
  return c.settings.exact_border && !m.corner.empty() && border_detail::role(c, a) == Role::Fixed &&
         border_detail::role(c, b) == Role::Fixed;
}

/// Pair p was refused a placement (pair_cost false): locked if it never_contracts, else blocked
/// (its ends' has_blocked are set by the caller, see PairSet::block).
inline PairState refused_state(const Context& c, std::uint32_t p) {
  return never_contracts(c, p) ? kLocked : kBlocked;
}

/// Marks pair p, refused a placement, locked or blocked (refused_state), in one thread: blocking
/// also flags its ends.
inline void refuse(Context& c, std::uint32_t p) {
  if (refused_state(c, p) == kBlocked) c.pairs.block(p);
  else c.pairs.pairs[p].state = kLocked;
}

/// The ranking key of pair p: the quadric error at its placement, plus, when inversions are
/// penalised and it would flip a face, a penalty that sorts it after every clean contraction.
inline bool pair_cost(const Context& c, std::uint32_t p, double& cost) {
  Quadric q;
  Placed placed;
  if (!place_pair(c, p, q, placed)) return false;
  cost = placed.error;
  if (c.settings.inversion == InversionPolicy::Penalize &&
      flips(c.mesh, c.pairs.pairs[p].v[0], c.pairs.pairs[p].v[1], placed.position, c.settings.cos_max_turn))
    cost += q.weight > 0 ? q.weight : 1;  // as if moved by a whole diagonal
  cost = round_key(cost);
  return true;
}

}  // namespace qem::core
