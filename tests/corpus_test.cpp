// Every mesh in ../shared/data, simplified at ratios 0.5, 0.1, 0.01 and to 100 faces, with t = 0
// and t > 0: no crash, no hang (a per-run time limit), a valid output (indices in range, no NaN,
// no degenerate or duplicate face), the face target hit or a clean "unreachable" report, and on a
// manifold input with t = 0 no new non-manifold edge. Skips when the shared folder is absent.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

#include "mesh_checks.h"
#include "qem/io.h"
#include "qem/simplify.h"
#include "test_meshes.h"

using namespace qem;

namespace {

std::vector<std::string> corpus_files() {
  std::vector<std::string> names;
  std::filesystem::path dir = std::filesystem::path(QEM_SHARED_DIR) / "data";
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    std::string ext = entry.path().extension().string();
    if (ext == ".obj" || ext == ".ply" || ext == ".stl" || ext == ".off") names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  if (names.empty()) names.push_back("(shared data absent)");
  return names;
}

#ifdef __SANITIZE_ADDRESS__
constexpr double kSecondsPerRun = 300;  // sanitizers slow everything down several times
#else
constexpr double kSecondsPerRun = 60;
#endif

class Corpus : public ::testing::TestWithParam<std::string> {};

TEST_P(Corpus, SimplifiesCleanlyAtEveryTarget) {
  const std::string path = test::shared_data(GetParam());
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  Mesh in = load_mesh(path);
  const std::size_t in_non_manifold = test::non_manifold_edges(in);

  struct Case {
    double ratio;
    std::size_t faces;
    double threshold_rel;
  };
  std::vector<Case> cases;
  for (double t : {0.0, 0.002}) {
    for (double r : {0.5, 0.1, 0.01}) cases.push_back({r, 0, t});
    cases.push_back({0, 100, t});
  }
  for (const Case& c : cases) {
    SCOPED_TRACE(GetParam() + " ratio " + std::to_string(c.ratio) + " faces " + std::to_string(c.faces) +
                 " t_rel " + std::to_string(c.threshold_rel));
    SimplifyOptions o;
    o.target_ratio = c.ratio;
    o.target_faces = c.faces;
    o.threshold = c.threshold_rel;
    o.threshold_is_relative = true;
    const auto start = std::chrono::steady_clock::now();
    ProgressCallback time_limit([&](double) {  // a hang becomes a cancelled run
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < kSecondsPerRun;
    });
    SimplifyResult r = simplify(in, o, &time_limit);
    ASSERT_NE(r.stop_reason, StopReason::Cancelled) << "took longer than " << kSecondsPerRun << " s";
    EXPECT_EQ(test::validity_problem(r.mesh, r.twin_faces), "");
    const std::size_t target = c.faces > 0 ? c.faces : std::size_t(c.ratio * double(r.input_faces));
    if (r.stop_reason == StopReason::TargetReached || r.stop_reason == StopReason::AlreadyBelowTarget) {
      EXPECT_LE(r.mesh.face_count(), std::max(target, r.input_faces <= target ? r.input_faces : target));
    } else {
      EXPECT_EQ(r.stop_reason, StopReason::NoValidPair);
      EXPECT_FALSE(r.stop_detail.empty());
      EXPECT_GT(r.mesh.face_count(), target);
    }
    if (c.threshold_rel == 0 && in_non_manifold == 0) {
      EXPECT_EQ(test::non_manifold_edges(r.mesh), 0u);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(SharedData, Corpus, ::testing::ValuesIn(corpus_files()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& ch : name)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return name;
                         });

}  // namespace
