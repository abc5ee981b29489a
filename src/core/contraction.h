// One contraction (GH97 §4 step 5), with its checks: try_contract checks pair p against the
// topology, component (component_guard.h), inversion and error limits and contracts it if it passes.
//
// The two orders keep the vertex lists and the costs differently; that difference, and nothing
// else, is the `Lists` parameter, which an order provides as:
//   for_each_pair_of(v, f)   calls f(r) for every pair r of v as the mesh is now (dead ones too)
//   pair_removed(p)          p died
//   pair_changed(p)          p's cost must be recomputed (at once, or before the next ranking)
//   contracted(a, b, faces, pairs)   b went into a, whose live faces and pairs are now these
// (order_greedy.cpp keeps the lists exact and re-keys its heap; order_passes.cpp leaves the lists
// as the pass found them and re-ranks at the next pass.) Templates, so the hot loop is compiled
// inside each order with no indirect call.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/collapse_checks.h"
#include "core/component_guard.h"
#include "core/context.h"
#include "core/cost_model.h"

namespace qem::core {

inline void kill_face(Context& c, std::uint32_t f, Worker& w) {
  c.mesh.face_alive[f] = 0;
  if (c.wedges)
    for (int k = 0; k < 3; ++k)
      c.wedges->move_corner(c.mesh.corner_wedge[3 * std::size_t(f) + k], kNoVertex, w.emptied_wedges);
  ++w.faces_killed;
  if (c.observe_contractions) w.dead_faces.push_back(c.mesh.face_source[f]);
}

// Face f (now on a) against a's own faces w.faces[0..own): on the same three vertices with the
// same orientation it is a duplicate and dies; with the opposite orientation the two are the
// touching walls of two aggregated parts (GH97 §3.2, Fig. 3) and both die, like glued faces.
// Without the link condition (preserve_topology off) a duplicate takes the other with it too: the
// surface passed there twice, and keeping one left its three edges with an odd count of faces, a
// crack where the input was closed (mod 2, a closed surface's contractions stay closed only if
// both go; the out-of-core run's pass past the clustering's folds relies on it).
inline bool kill_if_coincident(Context& c, std::uint32_t f, std::size_t own, Worker& w) {
  const WorkingMesh& m = c.mesh;
  const std::uint32_t* t = m.face(f);
  for (std::size_t i = 0; i < own; ++i) {
    const std::uint32_t g = w.faces[i];
    if (!m.face_alive[g] || !(m.face_has(g, t[0]) && m.face_has(g, t[1]) && m.face_has(g, t[2]))) continue;
    const std::uint32_t* u = m.face(g);
    int k = 0;
    while (u[k] != t[0]) ++k;
    const bool same_orientation = u[(k + 1) % 3] == t[1];
    kill_face(c, f, w);
    if (!same_orientation || !c.settings.preserve_topology) kill_face(c, g, w);
    return true;
  }
  return false;
}

// Faces: those containing both ends degenerate and die; b's others now use a. Where the topology
// check did not run (virtual pairs, or topology not preserved), a face can land on the same three
// vertices as one of a's: it dies too, so the output never has duplicate faces. Leaves a's live
// faces in w.faces.
inline void merge_faces(Context& c, std::uint32_t a, std::uint32_t b, bool may_duplicate, Worker& w) {
  WorkingMesh& m = c.mesh;
  std::vector<std::uint32_t>& faces = w.faces;
  faces.clear();
  for (std::uint32_t f : m.vertex_faces[a]) {
    if (!m.face_alive[f]) continue;
    if (m.face_has(f, b)) {
      kill_face(c, f, w);
      continue;
    }
    faces.push_back(f);
  }
  const std::size_t own = faces.size();
  for (std::uint32_t f : m.vertex_faces[b]) {
    if (!m.face_alive[f]) continue;
    std::uint32_t* t = &m.tri[3 * std::size_t(f)];
    for (int k = 0; k < 3; ++k)
      if (t[k] == b) {
        t[k] = a;
        if (c.wedges) {  // the corner's wedge goes with it to its partner at a (w.wedge_map)
          std::uint32_t& corner = m.corner_wedge[3 * std::size_t(f) + k];
          for (const auto& [removed, kept] : w.wedge_map)
            if (corner == removed) {
              c.wedges->move_corner(removed, kept, w.emptied_wedges);
              corner = kept;
              break;
            }
        }
      }
    if (may_duplicate && kill_if_coincident(c, f, own, w)) continue;
    faces.push_back(f);
  }
  if (may_duplicate) {  // drop the partners that cancelled
    std::size_t kept = 0;
    for (std::uint32_t f : faces)
      if (m.face_alive[f]) faces[kept++] = f;
    faces.resize(kept);
  }
}

// GH97 §4 "pair sets merge": b's pairs now start at a; the contracted pair and any pair that now
// duplicates another (same two vertices) are removed. Leaves a's pairs in w.pairs.
template <class Lists>
void merge_pairs(Context& c, Lists& lists, std::uint32_t p, std::uint32_t a, std::uint32_t b, Worker& w) {
  PairSet& ps = c.pairs;
  ps.pairs[p].state = kDead;
  lists.pair_removed(p);
  const std::uint32_t s = ++w.stamp;
  c.marks[a] = s;
  std::vector<std::uint32_t>& pairs = w.pairs;
  pairs.clear();
  for (int end = 0; end < 2; ++end) {
    for (std::uint32_t r : ps.vertex_pairs[end == 0 ? a : b]) {
      if (ps.pairs[r].state == kDead) continue;
      std::uint32_t* v = ps.pairs[r].v;
      if (v[0] == b) v[0] = a;
      if (v[1] == b) v[1] = a;
      const std::uint32_t o = v[0] == a ? v[1] : v[0];
      if (c.marks[o] == s) {  // duplicate of a pair already kept (or a degenerate (a, a) pair)
        ps.pairs[r].state = kDead;
        lists.pair_removed(r);
        continue;
      }
      c.marks[o] = s;
      if (v[0] > v[1]) std::swap(v[0], v[1]);
      pairs.push_back(r);
    }
  }
}

// The neighbourhood of v changed: pairs of v's neighbours that were rejected get another chance.
template <class Lists>
void unblock_around(Context& c, Lists& lists, std::uint32_t v) {
  PairSet& ps = c.pairs;
  lists.for_each_pair_of(v, [&](std::uint32_t p) {
    if (ps.pairs[p].state == kDead) return;
    const std::uint32_t o = ps.other_end(p, v);
    if (!ps.has_blocked[o]) return;
    ps.has_blocked[o] = 0;
    lists.for_each_pair_of(o, [&](std::uint32_t q) {
      if (ps.pairs[q].state == kBlocked) lists.pair_changed(q);
    });
  });
}

// GH97 §4 step 5: (a, b) -> a at `target`, with quadric q = Q_a + Q_b.
template <class Lists>
void contract(Context& c, Lists& lists, std::uint32_t p, const Quadric& q, const Vec3& target, Worker& w) {
  WorkingMesh& m = c.mesh;
  std::uint32_t a = c.pairs.pairs[p].v[0], b = c.pairs.pairs[p].v[1];
  // When the target is one of the ends (endpoint placement, a locked border vertex), that end
  // survives, so its exact input coordinates reach the output untouched.
  const auto same = [](const Vec3& x, const Vec3& y) { return x.x == y.x && x.y == y.y && x.z == y.z; };
  if (same(target, m.pos[b]) && !same(target, m.pos[a])) std::swap(a, b);
  const bool moves = !same(target, m.pos[a]);
  m.moved[a] |= moves;
  w.last_kept = a, w.last_removed = b;
  if (c.map) c.map->contracted(a, b);
  m.pos[a] = target;
  c.quadric[a] = q;
  m.boundary[a] |= m.boundary[b];
  // Exact borders: a hard corner is never removed nor moved (so never b); a soft corner that moves
  // or is removed is a corner no more (border_placement.h).
  if (!m.corner.empty() && m.corner[a] == kSoftCorner && moves) m.corner[a] = 0;
  ++w.vertices_removed;
  m.aggregated[a] |= m.aggregated[b] | c.pairs.pairs[p].is_virtual;

  bool crossed = false;  // permissive: the collapse crosses a seam
  if (c.wedges) map_wedges(m, *c.wedges, a, b, w.wedge_map, &crossed);  // checked by place_pair
  if (c.components) c.components->join(a, b);  // a threshold pair joins two parts into one
  const std::size_t killed_before = w.faces_killed;
  merge_faces(c, a, b, m.aggregated[a] || !c.settings.preserve_topology, w);
  if (c.components) c.components->faces_died(a, w.faces_killed - killed_before);
  merge_pairs(c, lists, p, a, b, w);
  if (c.wedges) {
    c.wedges->merge(a, b, moves, crossed, target, w.wedge_map, m, w.faces);
    c.wedges->drop_unused(w.emptied_wedges);  // a seam whose faces on one side all died is gone
  }
  lists.contracted(a, b, w.faces, w.pairs);
  // GH97 §4 step 5: update the costs of all valid pairs involving the new vertex.
  for (std::uint32_t r : w.pairs)
    if (c.pairs.pairs[r].state != kLocked) lists.pair_changed(r);
  unblock_around(c, lists, a);
}

// Tells the observer of the contraction just made (error in the working frame).
inline void report_contraction(Context& c, double error, Worker& w) {
  const WorkingMesh& m = c.mesh;
  const Vec3 p = m.output_position(w.last_kept, c.input);
  const Contraction event{m.source_vertex[w.last_kept], m.source_vertex[w.last_removed], {p.x, p.y, p.z},
                          error * m.frame.scale, w.dead_faces};
  c.observer->on_contraction(event);
  w.dead_faces.clear();
}

// Checks pair p against the topology, inversion and error limits and contracts it if it passes;
// otherwise it is blocked (retried when its neighbourhood changes) or, an edge whose faces all
// died, dropped.
template <class Lists>
bool try_contract(Context& c, Lists& lists, std::uint32_t p, Worker& w) {
  PairSet& ps = c.pairs;
  const std::uint32_t a = ps.pairs[p].v[0], b = ps.pairs[p].v[1];
  bool is_edge = false;
  // Exact borders: a small hole down to three vertices may close (border_placement.h, hole_closed_by).
  const std::uint32_t closes = c.settings.exact_border ? hole_closed_by(c.mesh, a, b) : kNoVertex;
  if (!link_condition_ok(c.mesh, a, b, c.settings.preserve_topology, is_edge, c.marks, w.stamp, closes)) {
    ++w.blocked_topology;
    ps.block(p);
    return false;
  }
  if (!is_edge && !ps.pairs[p].is_virtual) {
    // An edge pair whose faces all died: at t = 0 only edges are valid pairs (GH97 §3.2).
    ps.pairs[p].state = kDead;
    return false;
  }
  // As in contract(): faces may land on the same three vertices where the link condition did not run.
  const bool may_duplicate = c.mesh.aggregated[a] || c.mesh.aggregated[b] || ps.pairs[p].is_virtual ||
                             !c.settings.preserve_topology;
  if (c.components && !c.components->allows(c.mesh, a, b, may_duplicate)) {
    ++w.blocked_component;  // it would take a connected component below its floor
    ps.block(p);
    return false;
  }
  Quadric q;
  Placed placed;
  if (!place_pair(c, p, q, placed)) {  // with attributes: the seams around it changed
    ++w.blocked_topology;
    ps.block(p);
    return false;
  }
  // Exact borders: a border pair's cost depends on more than its two ends. Its placement is the
  // cheapest point that flips no face, so a neighbour's contraction can push it to a dearer one
  // (one that removes a corner, corner_error), a hole comes down to three vertices by a
  // contraction elsewhere on its loop (hole_error), and a border neighbour's slide or removal
  // moves the far end of the chords it would make (chord_error). None re-costs this pair, so when its cost
  // now exceeds the ranked one it is ranked again instead of being made out of order.
  if (c.settings.exact_border && (c.mesh.boundary[a] || c.mesh.boundary[b]) &&
      round_key(placed.error) > double(ps.cost[p])) {
    lists.pair_changed(p);
    return false;
  }
  if (c.settings.inversion == InversionPolicy::Forbid && flips(c.mesh, a, b, placed.position, c.settings.cos_max_turn)) {
    ++w.blocked_inversion;
    ps.block(p);
    return false;
  }
  const double err = normalized_error(placed.error, q.weight);
  if (err > c.settings.max_error) {
    ++w.blocked_error;
    ps.block(p);
    return false;
  }
  // max_distance: the new faces certified against the input (checked last: the costliest).
  if (c.surface && !contraction_within(*c.surface, c.settings.max_distance, c.mesh, a, b, placed.position)) {
    ++w.blocked_distance;
    ps.block(p);
    return false;
  }
  w.max_error = std::max(w.max_error, err);
  contract(c, lists, p, q, placed.position, w);
  // Exact borders: where the survivor lies on the input's border (it slid, or took the place of
  // the other end; an interior vertex that came to a border vertex takes that one's).
  if (!c.mesh.border_spot.empty() && placed.spot.from != kNoSlot) c.mesh.border_spot[w.last_kept] = placed.spot;
  if (closes != kNoVertex) {  // the hole is gone: its last vertices are interior now (unless on another border)
    update_border_after_closing(c.mesh, w.last_kept);
    update_border_after_closing(c.mesh, closes);
  }
  ++w.contractions;
  if (c.observe_contractions) report_contraction(c, err, w);
  return true;
}

}  // namespace qem::core
