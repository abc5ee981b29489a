// Connected components kept by default. GH97's contraction lets a small component contract to
// nothing, which lowers the mean error but silently drops whole parts (bolts, buttons, the loose
// pieces of a scan). The guard counts each component's live faces and refuses a contraction that
// would take a component below its floor:
//   - a closed component (no border edge) keeps 4 faces: a closed surface has at least a
//     tetrahedron's 4 (fewer would be two coincident faces, which a contraction kills together, or
//     an open fragment); with the link condition on, a closed manifold part cannot go below 4
//     anyway, so the guard matters at aggregation joints and with --allow-non-manifold;
//   - an open component keeps 1 face, the least that still shows where the part was.
// A component with fewer faces than its floor keeps the ones it has.
//
// Components are found once, on the working mesh (vertex-connected, as qem::mesh_info counts
// them: with attributes its vertices are the welded positions). A threshold pair (GH97 §3.2)
// whose contraction joins two components makes them one from that moment on: their counts add
// up and the larger floor applies.
//
// Threads: the pass order makes contractions on several threads (regions.h). Face counts are
// decremented atomically, and `risky` sends every pair of a band whose component could reach its
// floor in the band, and every pair that joins two components, to the band's one-by-one group:
// a pair made on a worker thread can never be refused by the guard, so the result does not
// depend on the thread count.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/pair_set.h"
#include "core/working_mesh.h"

namespace qem::core {

struct Wedges;

class ComponentGuard {
 public:
  /// The components of `mesh`'s live faces; closed ones are those with no boundary vertex
  /// (WorkingMesh::boundary must be set).
  explicit ComponentGuard(const WorkingMesh& mesh);

  /// The component of working vertex v now. Reads only: safe on worker threads.
  std::uint32_t root(std::uint32_t v) const;

  /// Whether contracting (a, b) leaves their component (or the two it joins) at or above its
  /// floor. `may_duplicate`: faces landing on the same three vertices die too (see
  /// contraction.h's merge_faces), so they are counted.
  bool allows(const WorkingMesh& m, std::uint32_t a, std::uint32_t b, bool may_duplicate) const;

  /// Before contracting (a, b): joins their components if they differ. One thread only.
  void join(std::uint32_t a, std::uint32_t b);
  /// `count` faces of v's component died.
  void faces_died(std::uint32_t v, std::size_t count) {
    if (count > 0) live_[root(v)].fetch_sub(std::uint32_t(count), std::memory_order_relaxed);
  }

  /// For each of a band's `count` pairs, whether it must be made one by one (see above): it joins
  /// two components, or its component has fewer live faces than its floor plus all the faces
  /// that the band's pairs in it could remove (each removes only faces of its two ends).
  void risky(const WorkingMesh& m, const PairSet& ps, const std::uint32_t* band, std::size_t count,
             std::vector<std::uint8_t>& out);

  /// Renumbering (renumber.h): working vertex v is now vertex_to[v].
  void renumber(const std::vector<std::uint32_t>& vertex_to, std::size_t count);

 private:
  std::vector<std::uint32_t> label_;  // per working vertex: its component as found at the start
  // Union by size over component ids (no path compression: find stays read-only, and the depth
  // stays below log2 of the component count).
  std::vector<std::uint32_t> parent_, size_;
  std::vector<std::atomic<std::uint32_t>> live_;  // per root: live faces
  std::vector<std::uint32_t> floor_;              // per root: faces it keeps at least
  std::vector<std::size_t> stake_;                // scratch of risky(), per root
};

/// The number of connected components of `mesh`'s live faces (vertex-connected).
std::size_t count_components(const WorkingMesh& mesh);

/// Removes the components whose bounding-box diagonal is below `size` (working frame): their
/// faces and vertices leave the working mesh (and the wedges, if any), which is renumbered
/// densely. Returns how many were removed.
std::size_t prune_components(WorkingMesh& mesh, Wedges* wedges, double size);

}  // namespace qem::core
