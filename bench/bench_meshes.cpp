// In-code benchmark meshes: see bench_meshes.h.
#include "bench_meshes.h"

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <numbers>
#include <unordered_map>
#include <vector>

#include "qem/io.h"

namespace qem::bench {
namespace {

// splitmix64: tiny, fixed, platform-independent, so the meshes are the same everywhere
// (std::uniform_real_distribution is not specified bit-exactly across standard libraries).
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)
};

Mesh unit_icosphere(int level) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  Mesh m;
  m.positions = {-1, t,  0,  1, t, 0,  -1, -t, 0,  1, -t, 0, 0,  -1, t,  0,  1, t,
                 0,  -1, -t, 0, 1, -t, t,  0,  -1, t, 0,  1, -t, 0,  -1, -t, 0, 1};
  m.indices = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
               4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
               6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
  auto normalize = [&](std::size_t v) {
    double* p = &m.positions[3 * v];
    const double l = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    p[0] /= l, p[1] /= l, p[2] /= l;
  };
  for (std::size_t v = 0; v < 12; ++v) normalize(v);
  for (int l = 0; l < level; ++l) {
    // Each edge is split once: V' = V + E = V + 3F/2.
    const std::size_t faces = m.face_count();
    std::unordered_map<std::uint64_t, std::uint32_t> mid;
    mid.reserve(faces * 3 / 2);
    m.positions.reserve(m.positions.size() + 3 * (faces * 3 / 2));
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const std::uint64_t key = a < b ? (std::uint64_t(a) << 32 | b) : (std::uint64_t(b) << 32 | a);
      auto [it, inserted] = mid.try_emplace(key, std::uint32_t(m.vertex_count()));
      if (inserted) {
        for (int k = 0; k < 3; ++k)
          m.positions.push_back((m.positions[3 * a + k] + m.positions[3 * b + k]) / 2);
        normalize(it->second);
      }
      return it->second;
    };
    std::vector<std::uint32_t> next;
    next.reserve(4 * m.indices.size());
    for (std::size_t f = 0; f < m.indices.size(); f += 3) {
      const std::uint32_t a = m.indices[f], b = m.indices[f + 1], c = m.indices[f + 2];
      const std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    m.indices = std::move(next);
  }
  return m;
}

Mesh make_bumpy_icosphere(int level) {
  Mesh m = unit_icosphere(level);
  SplitMix64 rng{1997};
  struct Wave {
    double d[3], frequency, phase, amplitude;
  };
  std::vector<Wave> waves;
  for (int j = 0; j < 12; ++j) {
    Wave w{};
    double n = 0;
    // A direction uniform on the sphere (rejection from the cube, then normalise).
    do {
      for (double& c : w.d) c = 2 * rng.uniform() - 1;
      n = std::sqrt(w.d[0] * w.d[0] + w.d[1] * w.d[1] + w.d[2] * w.d[2]);
    } while (n < 1e-3 || n > 1);
    for (double& c : w.d) c /= n;
    w.frequency = 2.0 + 3.0 * j + 2.0 * rng.uniform();  // wavelengths 2*pi/f: ~3 down to ~0.17
    w.phase = 2 * std::numbers::pi * rng.uniform();
    w.amplitude = 0.12 / w.frequency;
    waves.push_back(w);
  }
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    double* p = &m.positions[3 * v];
    double r = 1.0;
    for (const Wave& w : waves)
      r += w.amplitude * std::sin(w.frequency * (w.d[0] * p[0] + w.d[1] * p[1] + w.d[2] * p[2]) + w.phase);
    r += (rng.uniform() - 0.5) * 0.002;
    p[0] *= r, p[1] *= r, p[2] *= r;
  }
  return m;
}

// Removes the temporary PLY files when the benchmark exits.
struct TempFiles {
  std::map<int, std::string> paths;
  ~TempFiles() {
    std::error_code ec;
    for (auto& [level, path] : paths) std::filesystem::remove(path, ec);
  }
};

}  // namespace

const Mesh& bumpy_icosphere(int level) {
  static std::map<int, std::unique_ptr<Mesh>> cache;
  auto& slot = cache[level];
  if (!slot) slot = std::make_unique<Mesh>(make_bumpy_icosphere(level));
  return *slot;
}

const std::string& bumpy_icosphere_ply(int level) {
  static TempFiles files;
  auto it = files.paths.find(level);
  if (it != files.paths.end()) return it->second;
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("qem_bench_sphere_" + std::to_string(level) + "_" + std::to_string(::getpid()) + ".ply"))
          .string();
  SaveOptions save;
  save.binary = true;
  save_mesh(path, bumpy_icosphere(level), save);
  return files.paths.emplace(level, path).first->second;
}

}  // namespace qem::bench
