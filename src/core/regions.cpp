#include "core/regions.h"

#include "core/contraction.h"
#include "core/parallel_chunks.h"
#include "core/prefetch.h"

namespace qem::core {

void Regions::find_cut(const Context& c, const PassLists& lists) {
  const std::size_t n = c.mesh.vertex_count();
  region_scale_ = (std::uint64_t(kRegions) << 40) / std::max<std::size_t>(n, 1);
  cut_.assign(n, 0);
  near_cut_.assign(n, 0);
  for (const PairRecord& r : c.pairs.pairs)
    if (r.state != kDead && region_of(r.v[0]) != region_of(r.v[1])) mark_cut(lists, r.v[0]), mark_cut(lists, r.v[1]);
}

void Regions::mark_cut(const PassLists& lists, std::uint32_t v) {
  if (cut_[v]) return;
  cut_[v] = near_cut_[v] = 1;
  mark_neighbours_near(lists, v);
}

void Regions::mark_neighbours_near(const PassLists& lists, std::uint32_t v) {
  const PairSet& ps = lists.c.pairs;
  lists.for_each_pair_of(v, [&](std::uint32_t r) {
    if (ps.pairs[r].state != kDead) near_cut_[ps.other_end(r, v)] = 1;
  });
}

// After a contraction in the border group, whose survivor took over the other end's pairs: a pair
// it now has into another region puts both ends on the cut, and the survivor's new neighbours
// next to the cut (or on it) are marked near it. (Contractions inside a region change neither.)
void Regions::update_cut_after(const PassLists& lists, std::uint32_t a) {
  const PairSet& ps = lists.c.pairs;
  const std::uint32_t region = region_of(a);
  lists.for_each_pair_of(a, [&](std::uint32_t r) {
    if (ps.pairs[r].state == kDead) return;
    const std::uint32_t o = ps.other_end(r, a);
    if (region_of(o) != region) mark_cut(lists, a), mark_cut(lists, o);
    if (cut_[o]) near_cut_[a] = 1;
  });
  if (cut_[a]) mark_neighbours_near(lists, a);
}

// The pairs of one region, in order. One by one: stopping at the target, reporting progress and
// absorbing each contraction at once. Returns false if the observer cancelled.
bool Regions::make_region(Context& c, PassLists& lists, const std::vector<std::uint32_t>& pairs, Worker& w,
                          bool one_by_one) {
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (one_by_one && c.done()) break;
    if (one_by_one && !c.report_progress()) return false;
    prefetch_for_contraction(c, pairs.data(), pairs.size(), i);
    if (!ready_to_contract(c, lists.s, pairs[i])) continue;
    try_contract(c, lists, pairs[i], w);
    if (one_by_one) c.absorb(w);
  }
  return true;
}

// At most the faces contraction p may remove when it is made in this band. Where no two faces can
// land on the same three vertices (contract's merge_faces without duplicates), it removes the faces
// that have both ends, and no contraction before it in the band adds one: each vertex is in one
// pair of a pass, so another contraction only renames a third corner (a face on a, b and c stays
// one face on a, b and d), and a face of a and x that becomes one of b would need x to contract
// into b. So those faces counted now bound it, two on a manifold edge. Otherwise, every face of
// either end.
std::size_t Regions::faces_it_may_remove(const Context& c, std::uint32_t p) {
  const WorkingMesh& m = c.mesh;
  const PairRecord& r = c.pairs.pairs[p];
  const std::uint32_t a = r.v[0], b = r.v[1];
  if (m.aggregated[a] || m.aggregated[b] || r.is_virtual || !c.settings.preserve_topology)
    return m.vertex_faces[a].size() + m.vertex_faces[b].size();
  std::size_t shared = 0;
  for (std::uint32_t f : m.vertex_faces[a]) shared += m.face_alive[f] && m.face_has(f, b);
  return shared;
}

bool Regions::make_band(Context& c, PassLists& lists, const std::uint32_t* band, std::size_t count) {
  // Each pair to its region or to the border group.
  for (auto& pairs : inside_) pairs.clear();
  border_.clear();
  std::size_t faces_at_stake = 0;
  // Pairs the component guard might refuse, or that join two components, are made one by one
  // (component_guard.h): whether they are does not depend on the thread count.
  if (c.components) c.components->risky(c.mesh, c.pairs, band, count, risky_);
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t p = band[i], a = c.pairs.pairs[p].v[0], b = c.pairs.pairs[p].v[1];
    const std::uint32_t region = region_of(a);
    if (near_cut_[a] || near_cut_[b] || region_of(b) != region || (c.components && risky_[i])) {
      border_.push_back(p);
      continue;
    }
    inside_[region].push_back(p);
    faces_at_stake += faces_it_may_remove(c, p);
  }
  // Disjoint stamp ranges (each contraction takes 3 stamps), so every stamp stays unique.
  std::array<std::uint32_t, kRegions> first_stamp;
  for (std::uint32_t r = 0; r < kRegions; ++r) {
    first_stamp[r] = c.main.stamp;
    c.main.stamp += std::uint32_t(3 * inside_[r].size());
  }

  const std::size_t inside_count = count - border_.size();
  const bool parallel = c.settings.threads > 1 && !c.observe_contractions &&
                        c.mesh.faces_alive > c.settings.target_faces + faces_at_stake &&
                        c.mesh.vertices_alive > c.settings.target_vertices + inside_count;
  bool go_on = true;
  if (parallel) {
    std::array<Worker, kRegions> workers;
    for_chunks(kRegions, 1, std::min<unsigned>(c.settings.threads, kRegions), [&](std::size_t r, std::size_t, std::size_t) {
      workers[r].stamp = first_stamp[r];
      make_region(c, lists, inside_[r], workers[r], false);
    });
    for (Worker& w : workers) c.absorb(w);
    go_on = c.report_progress();
  } else {
    const std::uint32_t stamp = c.main.stamp;
    for (std::uint32_t r = 0; r < kRegions && go_on; ++r) {
      c.main.stamp = first_stamp[r];
      go_on = make_region(c, lists, inside_[r], c.main, true);
    }
    c.main.stamp = stamp;
  }

  // The border group, one by one.
  for (std::size_t i = 0; i < border_.size() && go_on; ++i) {
    if (c.done()) break;
    if (!c.report_progress()) return false;
    prefetch_for_contraction(c, border_.data(), border_.size(), i);
    if (!ready_to_contract(c, lists.s, border_[i]) || !try_contract(c, lists, border_[i], c.main)) continue;
    c.absorb(c.main);
    update_cut_after(lists, c.main.last_kept);
  }
  c.absorb(c.main);
  return go_on;
}

}  // namespace qem::core
