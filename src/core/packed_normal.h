// A unit normal in 4 bytes (octahedral encoding, Meyer et al. 2010 "On floating-point normal
// vectors"): what each working face keeps of its input face's orientation (collapse_checks.h),
// so the check costs 4 bytes per face instead of 12 or 24.
#pragma once

#include <cmath>
#include <cstdint>

#include "geometry/vec3.h"

namespace qem::core {

struct PackedNormal {
  std::int16_t u = 0, v = 0;
  static constexpr std::int16_t kNone = -32768;  ///< u: no normal (a face without area)

  /// n need not be unit; a zero n packs as "none".
  static PackedNormal pack(const Vec3& n) {
    const double l1 = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
    if (!(l1 > 0)) return {kNone, 0};
    double x = n.x / l1, y = n.y / l1;
    if (n.z < 0) {  // fold the lower half of the octahedron over the upper
      const double fx = (1 - std::abs(y)) * (x >= 0 ? 1 : -1), fy = (1 - std::abs(x)) * (y >= 0 ? 1 : -1);
      x = fx, y = fy;
    }
    return {round_half_away(x * 32767), round_half_away(y * 32767)};
  }
  /// std::lround for |x| <= 32767, without the library call: x - trunc(x) is exact.
  static std::int16_t round_half_away(double x) {
    if (!(std::abs(x) <= 32767)) return 0;  // NaN (an infinite normal), as lround's result cast
    const int t = int(x);
    const double rest = x - t;
    return std::int16_t(rest >= 0.5 ? t + 1 : rest <= -0.5 ? t - 1 : t);
  }
  bool none() const { return u == kNone; }
  /// The direction (not unit length).
  Vec3 unpack() const {
    double x = u / 32767.0, y = v / 32767.0;
    const double z = 1 - std::abs(x) - std::abs(y);
    if (z < 0) {
      const double fx = (1 - std::abs(y)) * (x >= 0 ? 1 : -1), fy = (1 - std::abs(x)) * (y >= 0 ? 1 : -1);
      x = fx, y = fy;
    }
    return {x, y, z};
  }
};

}  // namespace qem::core
