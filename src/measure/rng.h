// xoshiro256** seeded through splitmix64 (Blackman & Vigna): the same stream on every platform and
// compiler, unlike std:: distributions, so `qem measure` reports the same numbers everywhere. The
// generator and the draw of doubles match the benchmark's metric tool, so both sample the same points.
#pragma once

#include <cstdint>

namespace qem::measure_detail {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) {
    for (std::uint64_t& v : s_) v = splitmix(seed);
  }
  std::uint64_t next() {
    const std::uint64_t r = rotl(s_[1] * 5, 7) * 9, t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return r;
  }
  /// Uniform in [0, 1): the top 53 bits as a double.
  double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }

 private:
  static std::uint64_t splitmix(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t s_[4];
};

}  // namespace qem::measure_detail
