// The input's open borders as polylines, for exact borders (border_placement.h): a border vertex
// may slide along its own polyline, so each one knows where on the polylines it lies.
#pragma once

#include <cstdint>
#include <vector>

#include "geometry/vec3.h"

namespace qem::core {

/// "No slot": a vertex off the borders, a polyline end.
inline constexpr std::uint32_t kNoSlot = 0xffffffffu;

/// Where a border vertex lies on the input's border polylines: at input border vertex (slot)
/// `from` when `to` is kNoSlot, else on the input border edge from-to at parameter t in (0, 1).
struct BorderSpot {
  std::uint32_t from = kNoSlot, to = kNoSlot;
  double t = 0;
};

/// The input's border vertices ("slots"), each with its position (working frame) and its
/// neighbours along the border: two on a simple chain; a corner (border_placement.h) keeps at
/// most two and ends every walk along the chain.
struct BorderChains {
  std::vector<Vec3> pos;
  std::vector<std::uint32_t> neighbour;  ///< 2 per slot (kNoSlot: none)
  std::vector<std::uint8_t> corner;
  /// Per soft corner's slot: its size (border_placement.h, corner_error); 0 elsewhere.
  std::vector<double> corner_size;
  /// Per slot: half the bounding-box diagonal of its input border loop when that loop is a simple
  /// closed one (no hard corner on it), the size of the hole it bounds (border_placement.h,
  /// hole_error); infinity otherwise.
  std::vector<double> loop_radius;

  /// The point of `s`: computed the same way each time, so a vertex left at it keeps its bits.
  Vec3 at(const BorderSpot& s) const {
    if (s.to == kNoSlot) return pos[s.from];
    return pos[s.from] + (pos[s.to] - pos[s.from]) * s.t;
  }
};

}  // namespace qem::core
