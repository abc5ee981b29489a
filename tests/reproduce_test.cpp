// Tests of `qem reproduce` (src/reproduce): the SVG writer, the analytic ellipsoid curvatures, and a
// quick run of the paper experiments on the shared models (skipped when they are absent).
#include "reproduce/reproduce.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "qem/error.h"
#include "qem/io.h"
#include "reproduce/svg_plot.h"
#include "test_meshes.h"

namespace qem {
namespace {

namespace fs = std::filesystem;

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Reproduce, SvgHasAxesSeriesAndLegendAndIsDeterministic) {
  reproduce::Plot plot{"title <1>", "x", "y", true, true, {}, {}, false};
  plot.series.push_back(
      {"a & b", {1, 10, 100}, {1e-3, 1e-4, 1e-6}, {}, reproduce::Series::Style::LinePoints});
  plot.series.push_back(
      {"errors", {1, 10, 100}, {2e-3, 2e-4, 2e-6}, {1e-3, 1e-4, 1e-6}, reproduce::Series::Style::Points});
  const std::string svg = reproduce::render_svg(plot);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("<polyline"), std::string::npos);
  EXPECT_NE(svg.find("title &lt;1&gt;"), std::string::npos);
  EXPECT_NE(svg.find("a &amp; b"), std::string::npos);
  EXPECT_NE(svg.find(">1e-06<"), std::string::npos);  // a decade tick on the log axis
  EXPECT_EQ(svg, reproduce::render_svg(plot));
  reproduce::Plot bars{"bars", "", "v", false, false, {"one", "two"}, {}, false};
  bars.series.push_back({"s", {0, 1}, {3, 5}, {}, reproduce::Series::Style::Bars});
  const std::string bsvg = reproduce::render_svg(bars);
  EXPECT_EQ(std::count(bsvg.begin(), bsvg.end(), '\n') > 5, true);
  EXPECT_NE(bsvg.find(">two<"), std::string::npos);
  EXPECT_NE(bsvg.find("<rect x="), std::string::npos);
}

TEST(Reproduce, EllipsoidCurvaturesOfASphereAndAtTheAxes) {
  const double sphere[3] = {2, 2, 2}, p[3] = {0.3, -1, 4};
  double k1, k2;
  reproduce::ellipsoid_curvatures(sphere, p, k1, k2);
  EXPECT_NEAR(k1, 0.5, 1e-12);
  EXPECT_NEAR(k2, 0.5, 1e-12);
  // Ellipsoid 1, 2, 3 at the tip of the x axis: normal sections have radii b^2/a and c^2/a.
  const double axes[3] = {1, 2, 3}, tip[3] = {5, 0, 0};
  reproduce::ellipsoid_curvatures(axes, tip, k1, k2);
  EXPECT_NEAR(k1, 1.0 / 4, 1e-12);
  EXPECT_NEAR(k2, 1.0 / 9, 1e-12);
}

TEST(Reproduce, EllipsoidCurvaturesMatchTheSharedModelsProperties) {
  const std::string path = test::shared_data("synth_ellipsoid_11k_curv.ply");
  if (path.empty()) GTEST_SKIP() << "shared data folder absent";
  LoadOptions lo;
  lo.keep_vertex_properties = true;
  const Mesh m = load_mesh(path, lo);
  const VertexProperty* k1 = m.find_property("k1");
  const VertexProperty* k2 = m.find_property("k2");
  ASSERT_TRUE(k1 && k2);
  const double axes[3] = {1, 2, 3};
  for (std::size_t v = 0; v < m.vertex_count(); v += 37) {
    double a, b;
    reproduce::ellipsoid_curvatures(axes, &m.positions[3 * v], a, b);
    EXPECT_NEAR(a, k1->values[v], 1e-3 * k1->values[v] + 1e-5) << v;  // the file stores floats
    EXPECT_NEAR(b, k2->values[v], 1e-3 * k2->values[v] + 1e-5) << v;
  }
}

TEST(Reproduce, MissingDataFolderAndUnknownFigureAreErrors) {
  reproduce::Options o;
  o.data_dir = test::temp_dir() + "/no_such_folder";
  o.out_dir = test::temp_dir() + "/repro_missing";
  EXPECT_THROW(reproduce::run(o), Error);
  o.data_dir = test::temp_dir();
  o.only = {"gh97_fig99"};
  EXPECT_THROW(reproduce::run(o), Error);
  o.only = {"gh97_fig6"};  // folder exists but holds no cow
  EXPECT_THROW(reproduce::run(o), Error);
}

TEST(Reproduce, QuickRunReproducesThePapersOrdering) {
  const std::string cow = test::shared_data("gh_cow.obj");
  if (cow.empty()) GTEST_SKIP() << "shared data folder absent";
  reproduce::Options o;
  o.data_dir = fs::path(cow).parent_path().string();
  o.out_dir = test::temp_dir() + "/repro_quick";
  o.quick = true;
  o.only = {"gh97_fig6", "gh97_fig7", "gh97_fig15_17", "hg99_fig8"};
  const auto results = reproduce::run(o);
  ASSERT_EQ(results.size(), 4u);
  for (const auto& r : results) {
    ASSERT_EQ(r.files.size(), 3u) << r.id;
    for (const auto& f : r.files) {
      ASSERT_TRUE(fs::exists(f)) << f;
      EXPECT_GT(fs::file_size(f), 100u) << f;
    }
    EXPECT_EQ(read_all(r.files[2]).rfind("<svg", 0), 0u);
    EXPECT_NE(read_all(r.files[1]).find("|---|"), std::string::npos);
  }
  EXPECT_TRUE(fs::exists(o.out_dir + "/summary.md"));
  // GH97 Fig. 6: optimal placement beats the fixed choice at 500 faces.
  const auto& f6 = results[0].values;
  EXPECT_LT(f6.at("optimal_500"), f6.at("fixed_500"));
  EXPECT_GT(f6.at("fixed_500"), 0);
  for (std::size_t t : {10, 100, 500, 1000, 2000, 3000}) {
    EXPECT_TRUE(std::isfinite(f6.at("fixed_" + std::to_string(t))));
    EXPECT_GT(f6.at("optimal_" + std::to_string(t)), 0);
  }
  EXPECT_LT(f6.at("optimal_3000"), f6.at("optimal_10"));  // more faces, less error
  // GH97 Fig. 7: aggregation (t = 0.318) lowers E_250 below edge contraction alone.
  const auto& f7 = results[1].values;
  EXPECT_LT(f7.at("E_t0.318"), f7.at("E_t0"));
  // GH97 Figs. 15-17: pair contraction merges bones, edge contraction cannot.
  const auto& f15 = results[2].values;
  EXPECT_LT(f15.at("pair_components"), f15.at("edge_components"));
  EXPECT_LE(f15.at("edge_faces"), 250);
  EXPECT_LE(f15.at("pair_faces"), 250);
  EXPECT_GT(f15.at("cluster_faces"), 100);
  // HG99 Fig. 8: actual aspect ratios track the optimal ones.
  const auto& f8 = results[3].values;
  EXPECT_GT(f8.at("correlation"), 0.3);
  EXPECT_LE(f8.at("faces"), 800);
  EXPECT_GT(f8.at("faces"), 700);
  // Everything but timings is deterministic: a second run writes the same bytes.
  const std::string first = read_all(results[0].files[0]);
  o.only = {"gh97_fig6"};
  EXPECT_EQ(read_all(reproduce::run(o)[0].files[0]), first);
}

}  // namespace
}  // namespace qem
