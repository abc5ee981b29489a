#include "test_meshes.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace qem::test {

Mesh grid(int n) { return height_field(n, [](double, double) { return 0.0; }); }

Mesh height_field(int n, double (*f)(double, double)) {
  Mesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      double x = double(i) / n, y = double(j) / n;
      m.positions.insert(m.positions.end(), {x, y, f(x, y)});
    }
  auto id = [n](int i, int j) { return std::uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

Mesh icosphere(int level) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  Mesh m;
  m.positions = {-1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, 0, 0, -1, t, 0, 1, t,
                 0, -1, -t, 0, 1, -t, t, 0, -1, t, 0, 1, -t, 0, -1, -t, 0, 1};
  m.indices = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,
               3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
  auto normalize = [&](std::uint32_t v) {
    double* p = &m.positions[3 * v];
    double l = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    p[0] /= l, p[1] /= l, p[2] /= l;
  };
  for (std::uint32_t v = 0; v < 12; ++v) normalize(v);
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      std::uint32_t v = std::uint32_t(m.positions.size() / 3);
      for (int k = 0; k < 3; ++k) m.positions.push_back((m.positions[3 * a + k] + m.positions[3 * b + k]) / 2);
      normalize(v);
      mid[key] = v;
      return v;
    };
    std::vector<std::uint32_t> next;
    for (std::size_t f = 0; f < m.indices.size(); f += 3) {
      std::uint32_t a = m.indices[f], b = m.indices[f + 1], c = m.indices[f + 2];
      std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    m.indices = std::move(next);
  }
  return m;
}

Mesh cube() {
  Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  m.indices = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
               1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  return m;
}

Mesh tetrahedron() {
  Mesh m;
  m.positions = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
  m.indices = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};
  return m;
}

Mesh transformed(Mesh mesh, double scale, double ox, double oy, double oz) {
  const double o[3] = {ox, oy, oz};
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) mesh.positions[i] = mesh.positions[i] * scale + o[i % 3];
  return mesh;
}

Mesh concatenated(const Mesh& a, const Mesh& b) {
  Mesh m = a;
  std::uint32_t base = std::uint32_t(a.vertex_count());
  m.positions.insert(m.positions.end(), b.positions.begin(), b.positions.end());
  for (std::uint32_t i : b.indices) m.indices.push_back(i + base);
  return m;
}

std::string shared_data(const std::string& name) {
  std::filesystem::path p = std::filesystem::path(QEM_SHARED_DIR) / "data" / name;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

std::string temp_dir() {
  static std::string dir = [] {
    auto p = std::filesystem::temp_directory_path() / ("qem_tests_" + std::to_string(::getpid()));
    std::filesystem::remove_all(p);
    std::filesystem::create_directories(p);
    std::atexit([] {  // each test process removes its own folder
      std::error_code ec;
      std::filesystem::remove_all(
          std::filesystem::temp_directory_path() / ("qem_tests_" + std::to_string(::getpid())), ec);
    });
    return p.string();
  }();
  return dir;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int run_qem_quietly(const std::string& args) {
  const std::string cmd = std::string(QEM_CLI_PATH) + " " + args + " -q";
  return std::system(cmd.c_str());
}

}  // namespace qem::test
