// The simplifier's output bytes, pinned: a checksum of the output (positions, faces, error,
// contraction count, stop reason, and the contraction record where one is made) for a set of
// meshes, targets and options, both contraction orders, 1 and 2 threads, with and without
// threshold pairs and the refit. A change of the core that is meant to keep the output (a
// restructuring, a speed-up) must keep every checksum; a change that is meant to alter it updates
// tests/golden_checksums.txt with QEM_GOLDEN_WRITE=1 and says why in its commit.
//
// Meshes from ../shared/data are skipped when it is absent; the in-code ones always run.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "qem/io.h"
#include "qem/simplify.h"
#include "test_meshes.h"

using namespace qem;

namespace {

struct Fnv1a {
  std::uint64_t h = 1469598103934665603ull;
  void bytes(const void* data, std::size_t n) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  }
  template <class T>
  void array(const std::vector<T>& v) {
    const std::uint64_t n = v.size();
    bytes(&n, sizeof n);
    if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
  }
  template <class T>
  void value(T x) { bytes(&x, sizeof x); }
};

std::string checksum(const SimplifyResult& r, const ContractionLog* log) {
  Fnv1a f;
  f.array(r.mesh.positions);
  f.array(r.mesh.indices);
  f.value(r.max_error);
  f.value(std::uint64_t(r.contractions));
  f.value(int(r.stop_reason));
  if (log) {
    f.array(log->initial_faces), f.array(log->kept), f.array(log->removed);
    f.array(log->position), f.array(log->error), f.array(log->dead_begin), f.array(log->dead_faces);
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(f.h));
  return hex;
}

Mesh bumpy_sphere() {
  Mesh m = test::icosphere(5);  // 20,480 faces: both orders, and the passes reach the greedy tail
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    double* p = &m.positions[3 * v];
    const double r = 1 + 0.06 * std::sin(9 * p[0]) * std::sin(7 * p[1]) + 0.04 * std::cos(11 * p[2]);
    p[0] *= r, p[1] *= 1.3 * r, p[2] *= 0.8 * r;
  }
  return m;
}

Mesh bumpy_square() {  // open border, flat outside the bumps
  return test::height_field(60, [](double x, double y) {
    const double dx = x - 0.5, dy = y - 0.5;
    return 0.08 * std::exp(-30 * (dx * dx + dy * dy)) + 0.02 * std::sin(12 * x) * std::sin(10 * y) * x * (1 - x) * y * (1 - y) * 16;
  });
}

struct Config {
  std::string name;
  SimplifyOptions options;
  bool record = false;
};

std::vector<Config> configs(std::size_t faces) {
  std::vector<Config> out;
  auto add = [&](std::string name, auto edit, bool record = false) {
    Config c{std::move(name), {}, record};
    edit(c.options);
    out.push_back(std::move(c));
  };
  for (const char* order : {"passes", "greedy"})
    for (unsigned threads : {1u, 2u})
      for (double ratio : {0.1, 0.01}) {
        const std::size_t target = std::max<std::size_t>(std::size_t(double(faces) * ratio), 20);
        const std::string base = std::string(order) + "/t" + std::to_string(threads) + "/" +
                                 std::to_string(target);
        auto common = [&](SimplifyOptions& o) {
          o.scheme = std::strcmp(order, "passes") == 0 ? Scheme::Passes : Scheme::Greedy;
          o.threads = threads;
          o.target_faces = target;
        };
        add(base, common);
        add(base + "/threshold", [&](SimplifyOptions& o) {
          common(o);
          o.threshold = 0.02, o.threshold_is_relative = true;
        });
        add(base + "/light-refit", [&](SimplifyOptions& o) {
          common(o);
          o.refit_rounds = 2, o.refit_points_per_vertex = 8;  // the default light refit's, every target
        });
      }
  // One of each other option, in the default order.
  auto fixed = [&](SimplifyOptions& o) { o.target_ratio = 0.05; };
  add("passes/full-refit", [&](SimplifyOptions& o) { fixed(o), o.refit_rounds = 3; });
  add("passes/record", fixed, true);
  add("greedy/record", [&](SimplifyOptions& o) { fixed(o), o.scheme = Scheme::Greedy; }, true);
  add("passes/no-tail", [&](SimplifyOptions& o) { fixed(o), o.greedy_below_faces = 0; });
  add("passes/forget", [&](SimplifyOptions& o) { fixed(o), o.forget = 0.85, o.greedy_below_faces = 4000; }, true);
  add("passes/lock-border", [&](SimplifyOptions& o) { fixed(o), o.lock_border = true; });
  add("passes/penalize", [&](SimplifyOptions& o) { fixed(o), o.inversion = InversionPolicy::Penalize; });
  add("passes/uniform-endpoints", [&](SimplifyOptions& o) {
    fixed(o), o.weighting = Weighting::Uniform, o.placement = Placement::Endpoints;
  });
  add("passes/angle-segment", [&](SimplifyOptions& o) {
    fixed(o), o.weighting = Weighting::Angle, o.placement = Placement::Segment;
  });
  add("passes/max-error", [&](SimplifyOptions& o) { o.max_error = 0.004, o.max_error_is_relative = true; });
  add("passes/non-manifold", [&](SimplifyOptions& o) { fixed(o), o.preserve_topology = false; });
  add("greedy/vertices", [&](SimplifyOptions& o) {
    o.scheme = Scheme::Greedy, o.target_vertices = 200, o.boundary_weight = 0;
  });
  return out;
}

std::string golden_path() { return std::string(QEM_SOURCE_DIR) + "/tests/golden_checksums.txt"; }

std::map<std::string, std::string> read_golden() {
  std::map<std::string, std::string> out;
  std::ifstream in(golden_path());
  std::string key, value;
  while (in >> key >> value) out[key] = value;
  return out;
}

// The checksums of every config on one mesh; compared with (or, with QEM_GOLDEN_WRITE=1, written
// to) tests/golden_checksums.txt.
void check_mesh(const std::string& mesh_name, const Mesh& mesh) {
  const bool write = std::getenv("QEM_GOLDEN_WRITE") != nullptr;
  std::map<std::string, std::string> golden = read_golden();
  for (const Config& c : configs(mesh.face_count())) {
    SimplifyOptions o = c.options;
    ContractionRecorder recorder;
    const SimplifyResult r = simplify(MeshView(mesh), o, c.record ? &recorder : nullptr);
    const std::string key = mesh_name + ":" + c.name;
    const std::string sum = checksum(r, c.record ? &recorder.log : nullptr);
    if (write) {
      golden[key] = sum;
      continue;
    }
    auto it = golden.find(key);
    ASSERT_NE(it, golden.end()) << key << " has no golden checksum (QEM_GOLDEN_WRITE=1 records it)";
    EXPECT_EQ(sum, it->second) << key << ": the output changed";
  }
  if (write) {
    std::ofstream out(golden_path());
    for (const auto& [key, value] : golden) out << key << ' ' << value << '\n';
  }
}

class Golden : public ::testing::TestWithParam<std::string> {};

TEST_P(Golden, OutputBytesUnchanged) {
  const std::string name = GetParam();
  Mesh mesh;
  if (name == "bumpy_sphere") mesh = bumpy_sphere();
  else if (name == "bumpy_square") mesh = bumpy_square();
  else {
    const std::string path = test::shared_data(name);
    if (path.empty()) GTEST_SKIP() << "../shared/data not found";
    // Positions only: the checksums are of the simplifier's output for these positions and faces,
    // which the wedges of trimesh_chair.obj's vt indices would change (they split its UV seams).
    LoadOptions positions_only;
    positions_only.read_attributes = false;
    mesh = load_mesh(path, positions_only);
  }
  check_mesh(name, mesh);
}

INSTANTIATE_TEST_SUITE_P(Meshes, Golden,
                         ::testing::Values("bumpy_sphere", "bumpy_square", "gh_bunny_zipper.ply",
                                           "gh_foot_bones.off", "gh_cow.obj", "fandisk.obj",
                                           "trimesh_chair.obj", "tiny_non_manifold_wrap.obj"),
                         [](const auto& info) {
                           std::string s = info.param;
                           for (char& ch : s)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return s;
                         });

}  // namespace
