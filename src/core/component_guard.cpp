#include "core/component_guard.h"

#include <algorithm>
#include <limits>

#include "analysis/disjoint_sets.h"
#include "core/wedges.h"

namespace qem::core {

namespace {

// Each working vertex's component among the live faces (kNoVertex: on none), numbered 0.. in
// vertex order; returns the count.
std::uint32_t label_components(const WorkingMesh& m, std::vector<std::uint32_t>& label) {
  analysis::DisjointSets sets(m.vertex_count());
  for (std::uint32_t f = 0; f < m.face_alive.size(); ++f)
    if (m.face_alive[f]) {
      const std::uint32_t* t = m.face(f);
      sets.unite(t[0], t[1]), sets.unite(t[0], t[2]);
    }
  std::vector<std::uint8_t> used(m.vertex_count(), 0);
  for (std::uint32_t f = 0; f < m.face_alive.size(); ++f)
    if (m.face_alive[f])
      for (int k = 0; k < 3; ++k) used[m.face(f)[k]] = 1;
  label.assign(m.vertex_count(), kNoVertex);
  std::uint32_t count = 0;
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v)  // a root is its set's lowest vertex
    if (used[v] && sets.find(v) == v) label[v] = count++;
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v)
    if (used[v]) label[v] = label[sets.find(v)];
  return count;
}

}  // namespace

ComponentGuard::ComponentGuard(const WorkingMesh& m) {
  const std::uint32_t n = label_components(m, label_);
  parent_.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) parent_[i] = i;
  size_.assign(n, 1);
  live_ = std::vector<std::atomic<std::uint32_t>>(n);
  std::vector<std::uint8_t> open(n, 0);
  std::vector<std::uint32_t> faces(n, 0);
  for (std::uint32_t f = 0; f < m.face_alive.size(); ++f)
    if (m.face_alive[f]) ++faces[label_[m.face(f)[0]]];
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v)
    if (label_[v] != kNoVertex && m.boundary[v]) open[label_[v]] = 1;
  floor_.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    live_[i].store(faces[i], std::memory_order_relaxed);
    floor_[i] = std::min<std::uint32_t>(faces[i], open[i] ? 1 : 4);
  }
  stake_.assign(n, 0);
}

std::uint32_t ComponentGuard::root(std::uint32_t v) const {
  std::uint32_t x = label_[v];
  while (parent_[x] != x) x = parent_[x];
  return x;
}

bool ComponentGuard::allows(const WorkingMesh& m, std::uint32_t a, std::uint32_t b,
                            bool may_duplicate) const {
  if (label_[a] == kNoVertex || label_[b] == kNoVertex) return true;  // not on a face: nothing to lose
  const std::uint32_t ra = root(a), rb = root(b);
  std::size_t live = live_[ra].load(std::memory_order_relaxed);
  std::uint32_t floor = floor_[ra];
  if (rb != ra) live += live_[rb].load(std::memory_order_relaxed), floor = std::max(floor, floor_[rb]);
  // Every face that dies is one of a's or b's.
  if (live >= floor + m.vertex_faces[a].size() + m.vertex_faces[b].size()) return true;
  std::size_t dying = 0;
  for (std::uint32_t f : m.vertex_faces[a])
    if (m.face_alive[f] && m.face_has(f, b)) ++dying;
  if (may_duplicate) {
    // As merge_faces: a face of b's landing on the three vertices of one of a's dies, and so does
    // a's too when the two are oriented oppositely (kill_if_coincident).
    std::vector<std::uint32_t> gone;  // a's faces that die with a partner of b's
    for (std::uint32_t f : m.vertex_faces[b]) {
      if (!m.face_alive[f] || m.face_has(f, a)) continue;
      std::uint32_t t[3];
      for (int k = 0; k < 3; ++k) t[k] = m.face(f)[k] == b ? a : m.face(f)[k];
      for (std::uint32_t g : m.vertex_faces[a]) {
        if (!m.face_alive[g] || m.face_has(g, b) || std::find(gone.begin(), gone.end(), g) != gone.end())
          continue;
        if (!(m.face_has(g, t[0]) && m.face_has(g, t[1]) && m.face_has(g, t[2]))) continue;
        const std::uint32_t* u = m.face(g);
        int k = 0;
        while (u[k] != t[0]) ++k;
        ++dying;
        if (u[(k + 1) % 3] != t[1]) ++dying, gone.push_back(g);
        break;
      }
    }
  }
  return live >= floor + dying;
}

void ComponentGuard::join(std::uint32_t a, std::uint32_t b) {
  if (label_[a] == kNoVertex || label_[b] == kNoVertex) {  // a vertex on no face takes the other's part
    if (label_[a] == kNoVertex) label_[a] = label_[b];
    return;
  }
  std::uint32_t ra = root(a), rb = root(b);
  if (ra == rb) return;
  if (size_[ra] < size_[rb] || (size_[ra] == size_[rb] && rb < ra)) std::swap(ra, rb);
  parent_[rb] = ra;
  size_[ra] += size_[rb];
  live_[ra].fetch_add(live_[rb].load(std::memory_order_relaxed), std::memory_order_relaxed);
  live_[rb].store(0, std::memory_order_relaxed);
  floor_[ra] = std::max(floor_[ra], floor_[rb]);
}

void ComponentGuard::risky(const WorkingMesh& m, const PairSet& ps, const std::uint32_t* band,
                           std::size_t count, std::vector<std::uint8_t>& out) {
  out.assign(count, 0);
  const auto stake_of = [&](std::uint32_t a, std::uint32_t b) {
    return m.vertex_faces[a].size() + m.vertex_faces[b].size();
  };
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t a = ps.pairs[band[i]].v[0], b = ps.pairs[band[i]].v[1];
    if (label_[a] == kNoVertex || label_[b] == kNoVertex) {  // join() writes its label
      out[i] = 1;
      continue;
    }
    const std::uint32_t r = root(a);
    if (root(b) != r)
      out[i] = 1;
    else
      stake_[r] += stake_of(a, b);
  }
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t a = ps.pairs[band[i]].v[0];
    if (out[i]) continue;
    const std::uint32_t r = root(a);
    out[i] = live_[r].load(std::memory_order_relaxed) < floor_[r] + stake_[r];
  }
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t a = ps.pairs[band[i]].v[0], b = ps.pairs[band[i]].v[1];
    if (label_[a] != kNoVertex && label_[b] != kNoVertex) stake_[root(a)] = 0;
  }
}

void ComponentGuard::renumber(const std::vector<std::uint32_t>& vertex_to, std::size_t count) {
  squeeze_by(vertex_to, count, label_);
}

std::size_t count_components(const WorkingMesh& m) {
  std::vector<std::uint32_t> label;
  return label_components(m, label);
}

std::size_t prune_components(WorkingMesh& m, Wedges* wedges, double size) {
  std::vector<std::uint32_t> label;
  const std::uint32_t n = label_components(m, label);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<Vec3> lo(n, Vec3(kInf, kInf, kInf)), hi(n, Vec3(-kInf, -kInf, -kInf));
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v) {
    if (label[v] == kNoVertex) continue;
    Vec3& l = lo[label[v]];
    Vec3& h = hi[label[v]];
    const Vec3& p = m.pos[v];
    l = Vec3(std::min(l.x, p.x), std::min(l.y, p.y), std::min(l.z, p.z));
    h = Vec3(std::max(h.x, p.x), std::max(h.y, p.y), std::max(h.z, p.z));
  }
  std::vector<std::uint8_t> small(n, 0);
  std::size_t pruned = 0;
  for (std::uint32_t i = 0; i < n; ++i)
    if (length(hi[i] - lo[i]) < size) small[i] = 1, ++pruned;
  if (pruned == 0) return 0;
  for (std::uint32_t f = 0; f < m.face_alive.size(); ++f)
    if (m.face_alive[f] && small[label[m.face(f)[0]]]) m.face_alive[f] = 0, --m.faces_alive;
  // The vertices of the pruned parts go; the others are numbered densely, in order.
  std::vector<std::uint32_t> vertex_to(m.vertex_count(), kNoVertex);
  std::uint32_t count = 0;
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v)
    if (label[v] != kNoVertex && !small[label[v]]) vertex_to[v] = count++;
  m.squeeze_faces(vertex_to);
  m.squeeze_vertices(vertex_to, count);
  m.vertices_alive = count;
  if (wedges) wedges->renumber(vertex_to, count);
  return pruned;
}

}  // namespace qem::core
