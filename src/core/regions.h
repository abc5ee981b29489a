// The regions a pass's band is made in, several at once: the vertices split into kRegions ranges
// of ids (ids follow the Morton order, so each range is a compact part of the surface). A pair
// lies inside its region when neither end is on the cut (a vertex with a pair into another region)
// or next to it. Everything its contraction reads or writes (the faces and pairs of its ends,
// their neighbours' flags and pairs) is then within two steps of its ends, so inside its region
// (the vertex lists are only read during a pass); and contractions inside a region never create a
// pair to another one, so this stays true through the band. So the regions can be made at the
// same time on several threads, with exactly the result of making them one after another.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/context.h"
#include "core/order_passes.h"

namespace qem::core {

class Regions {
 public:
  static constexpr std::uint32_t kRegions = 8;

  /// Marks the cut and the vertices next to it (or more: a superset is safe). Once a pass: the
  /// vertex ids change between passes; make_band keeps it up to date.
  void find_cut(const Context& c, const PassLists& lists);

  /// Makes `count` chosen pairs (one band of a pass) in a fixed schedule that does not depend on
  /// the thread count: first, region by region, the pairs inside a region, then the pairs near or
  /// across region borders, each group in the band's order. The regions run on several threads
  /// unless the band could reach the target (the run must stop at exactly the same contraction)
  /// or the contractions are observed; then one after another, in the same schedule.
  /// Returns false if the observer cancelled.
  bool make_band(Context& c, PassLists& lists, const std::uint32_t* band, std::size_t count);

 private:
  static std::size_t faces_it_may_remove(const Context& c, std::uint32_t p);
  std::uint32_t region_of(std::uint32_t v) const { return std::uint32_t((v * region_scale_) >> 40); }
  void mark_cut(const PassLists& lists, std::uint32_t v);
  void mark_neighbours_near(const PassLists& lists, std::uint32_t v);
  void update_cut_after(const PassLists& lists, std::uint32_t survivor);
  bool make_region(Context& c, PassLists& lists, const std::vector<std::uint32_t>& pairs, Worker& w,
                   bool one_by_one);

  std::uint64_t region_scale_ = 0;  // floor(2^40 kRegions / vertex count): no division per lookup
  std::vector<std::uint8_t> cut_, near_cut_;
  std::array<std::vector<std::uint32_t>, kRegions> inside_;
  std::vector<std::uint32_t> border_;
  std::vector<std::uint8_t> risky_;  // per pair of the band (ComponentGuard::risky)
};

}  // namespace qem::core
