#include "core/cost_model.h"

#include <algorithm>

namespace qem::core {

bool place_with_wedges(const Context& c, std::uint32_t a, std::uint32_t b, const Quadric& q, Placed& placed) {
  // Scratch space per thread (pair costs are computed on several threads): no allocation per pair.
  thread_local std::vector<std::pair<std::uint32_t, std::uint32_t>> map;
  thread_local std::vector<std::uint32_t> partners;
  const Wedges& wg = *c.wedges;
  const WorkingMesh& m = c.mesh;
  bool found = false;
  const BorderTarget border = border_target(c, a, b);  // exact borders (border_placement.h)
  if (border == BorderTarget::Never) return false;
  for (int direction = 0; direction < 2; ++direction) {
    const std::uint32_t survivor = direction == 0 ? a : b, removed = direction == 0 ? b : a;
    if (m.held(removed, c.settings.lock_border)) continue;  // locked: it must stay
    if ((border == BorderTarget::AtA && survivor != a) || (border == BorderTarget::AtB && survivor != b)) continue;
    bool crossed = false;
    if (!map_wedges(m, wg, survivor, removed, map, &crossed)) continue;
    const bool free = wg.single(a) && wg.single(b) && !m.held(survivor, c.settings.lock_border) &&
                      border == BorderTarget::Free;
    Quadric total = q;
    double crossing_error = 0;  // a crossing whose survivor stays: its wedges keep their values
    std::uint32_t w = wg.first[survivor];
    do {
      partners.clear();
      for (const auto& [r, s] : map)
        if (s == w) partners.push_back(r);
      if (crossed && !free)
        crossing_error += (wg.permissive ? 1 : kJunctionCrossingWeight) *
                          wg.error_at(w, partners.data(), partners.size(), m.pos[survivor]);
      else
        total += wg.reduced(w, partners.data(), partners.size());
      w = wg.next[w];
    } while (w != wg.first[survivor]);
    const Placed candidate =
        free ? place(total, m.pos[a], m.pos[b], c.settings.placement)
             : Placed{m.pos[survivor],
                      std::max({total.evaluate(m.pos[survivor]) + crossing_error, corner_error(c, a, b, m.pos[survivor], q.weight),
                                chord_error(c, a, b, m.pos[survivor], m.border_spot.empty() ? BorderSpot{} : m.border_spot[survivor],
                                            q.weight)})};
    if (!found || candidate.error < placed.error) placed = candidate;
    found = true;
    if (free) break;  // both directions place the same way
  }
  return found;
}

}  // namespace qem::core
