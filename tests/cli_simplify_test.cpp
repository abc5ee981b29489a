// `qem simplify` as a user runs it: JSON line, summary, exit codes, nothing lost on failure.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "qem/io.h"
#include "test_meshes.h"

using namespace qem;
namespace fs = std::filesystem;

namespace {

struct CliRun {
  int exit_code;
  std::string out;  // stdout and stderr together
};

CliRun run(const std::string& args) {
  std::string cmd = std::string(QEM_CLI_PATH) + " " + args + " 2>&1";
  CliRun r{-1, {}};
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), pipe)) r.out.append(buf.data(), n);
  int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string sphere_file() {
  static std::string path = [] {
    std::string p = test::temp_dir() + "/cli_sphere.ply";
    save_mesh(p, test::icosphere(4));
    return p;
  }();
  return path;
}

TEST(CliSimplify, JsonLineHasTheHarnessFields) {
  const std::string out = test::temp_dir() + "/cli_out.ply";
  CliRun r = run("simplify " + sphere_file() + " " + out + " --faces 500 --json --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  for (const char* field : {"\"tool\":\"qem\"", "\"in_faces\":5120", "\"out_faces\":500", "\"out_vertices\":",
                            "\"load_s\":", "\"simplify_s\":", "\"write_s\":", "\"peak_rss_mb\":", "\"max_error\":"})
    EXPECT_NE(r.out.find(field), std::string::npos) << field << " missing in " << r.out;
  EXPECT_EQ(load_mesh(out).face_count(), 500u);
}

TEST(CliSimplify, DroppedInputFacesAreReported) {
  Mesh in = test::icosphere(3);
  in.indices.insert(in.indices.end(), {in.indices[0], in.indices[0], in.indices[1]});  // degenerate
  for (int k : {0, 1, 2, 3, 4, 5}) in.indices.push_back(in.indices[k]);              // two duplicates
  const std::string dir = test::temp_dir();
  save_mesh(dir + "/dropped.obj", in);
  CliRun r = run("simplify " + dir + "/dropped.obj " + dir + "/dropped_out.obj --faces 100 --json --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("\"dropped_degenerate\":1,"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"dropped_duplicate\":2,"), std::string::npos) << r.out;
  r = run("simplify " + dir + "/dropped.obj " + dir + "/dropped_out.obj --faces 100");
  EXPECT_NE(r.out.find("left out 1 degenerate and 2 duplicate input faces"), std::string::npos) << r.out;
}

TEST(CliSimplify, SummaryLineSaysWhyItStopped) {
  const std::string out = test::temp_dir() + "/cli_tetra.obj";
  save_mesh(test::temp_dir() + "/tetra.obj", test::tetrahedron());
  CliRun r = run("simplify " + test::temp_dir() + "/tetra.obj " + out + " --faces 1");
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("no valid contraction left"), std::string::npos) << r.out;
}

TEST(CliSimplify, SameOutputBytesTwice) {
  const std::string a = test::temp_dir() + "/cli_a.ply", b = test::temp_dir() + "/cli_b.ply";
  ASSERT_EQ(run("simplify " + sphere_file() + " " + a + " --ratio 0.2 -q").exit_code, 0);
  ASSERT_EQ(run("simplify " + sphere_file() + " " + b + " --ratio 0.2 -q").exit_code, 0);
  EXPECT_EQ(slurp(a), slurp(b));
}

TEST(CliSimplify, RefusesToOverwriteTheInput) {
  const std::string in = test::temp_dir() + "/cli_keep.ply";
  fs::copy_file(sphere_file(), in, fs::copy_options::overwrite_existing);
  const std::string before = slurp(in);
  CliRun r = run("simplify " + in + " " + in + " --faces 100");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.out.find("--force"), std::string::npos) << r.out;
  EXPECT_EQ(slurp(in), before);
  EXPECT_EQ(run("simplify " + in + " " + in + " --faces 100 --force -q").exit_code, 0);
  EXPECT_EQ(load_mesh(in).face_count(), 100u);
}

TEST(CliSimplify, FailedRunLeavesNoOutputAndNamesTheProblem) {
  const std::string bad = test::temp_dir() + "/cli_bad.obj";
  std::ofstream(bad) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n";
  const std::string out = test::temp_dir() + "/cli_never.ply";
  CliRun r = run("simplify " + bad + " " + out + " --faces 1");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("cli_bad.obj"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("line 4"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out));
  // No leftover temporary files beside the target either.
  for (const auto& e : fs::directory_iterator(test::temp_dir()))
    EXPECT_EQ(e.path().filename().string().find("cli_never"), std::string::npos) << e.path();
}

TEST(CliSimplify, ReaderWarningsArePrinted) {
  // An old Blender PLY: its credit line has no `comment` keyword, so the reader skips it and says so.
  const std::string in = test::temp_dir() + "/cli_blender.ply",
                    out = test::temp_dir() + "/cli_blender_out.obj";
  std::ofstream(in) << "ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org\nelement vertex 4\n"
                       "property float x\nproperty float y\nproperty float z\nelement face 2\n"
                       "property list uchar int vertex_indices\nend_header\n"
                       "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
  const std::string warning = in + ", line 3: unknown PLY header keyword 'Created', line skipped";
  // On stderr, even with --quiet (which silences progress and the summary, not news of the input).
  CliRun r = run("simplify " + in + " " + out + " --faces 1 --quiet");
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("qem: warning: " + warning + "\n"), std::string::npos) << r.out;
  // `qem info` lists it in its report and in its JSON.
  r = run("info " + in);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("  warning                " + warning + "\n"), std::string::npos) << r.out;
  r = run("info --json " + in);  // the temporary folder's path needs no JSON escaping
  EXPECT_NE(r.out.find("\"warnings\":[\"" + warning + "\"]"), std::string::npos) << r.out;
  EXPECT_NE(run("info --json " + sphere_file()).out.find("\"warnings\":[]"), std::string::npos);
}

TEST(CliSimplify, DoublePlyInputGivesDoublePlyOutput) {
  // Georeferenced coordinates (UTM northings near 5e6 m) lose centimetres in float: a PLY that
  // stores doubles is written back with doubles, and --double asks for them on any input.
  Mesh m = test::icosphere(3);
  for (std::size_t i = 0; i < m.positions.size(); i += 3) m.positions[i + 1] += 5123456.789;
  const std::string in = test::temp_dir() + "/cli_utm.ply", out = test::temp_dir() + "/cli_utm_out.ply";
  SaveOptions o;
  o.double_precision = true;
  save_mesh(in, m, o);
  ASSERT_EQ(run("simplify " + in + " " + out + " --faces 200 --quiet").exit_code, 0);
  LoadReport report;
  Mesh simplified = load_mesh(out, {}, &report);
  EXPECT_TRUE(report.double_precision);
  EXPECT_EQ(simplified.face_count(), 200u);
  bool sub_float_detail = false;  // some coordinate that float would have rounded
  for (double c : simplified.positions) sub_float_detail |= double(float(c)) != c;
  EXPECT_TRUE(sub_float_detail);
  // `qem cluster` and `qem measure --per-vertex` keep a double PLY double too.
  ASSERT_EQ(run("cluster " + in + " " + out + " --grid 8 8 8").exit_code, 0);
  load_mesh(out, {}, &report);
  EXPECT_TRUE(report.double_precision);
  const std::string per_vertex = test::temp_dir() + "/cli_utm_distance.ply";
  ASSERT_EQ(run("measure " + in + " " + out + " --samples 1000 --per-vertex " + per_vertex).exit_code, 0);
  load_mesh(per_vertex, {}, &report);
  EXPECT_TRUE(report.double_precision);

  ASSERT_EQ(run("simplify " + sphere_file() + " " + out + " --faces 200 --quiet").exit_code, 0);
  load_mesh(out, {}, &report);
  EXPECT_FALSE(report.double_precision);
  ASSERT_EQ(run("simplify " + sphere_file() + " " + out + " --faces 200 --quiet --double").exit_code, 0);
  load_mesh(out, {}, &report);
  EXPECT_TRUE(report.double_precision);
}

TEST(CliSimplify, BadOptionsAreRejected) {
  const std::string out = test::temp_dir() + "/cli_opt.ply";
  EXPECT_NE(run("simplify " + sphere_file() + " " + out).exit_code, 0);  // no target
  EXPECT_NE(run("simplify " + sphere_file() + " " + out + " --faces 10 --placement best").exit_code, 0);
  EXPECT_NE(run("simplify " + sphere_file() + " " + out + " --ratio 1.5").exit_code, 0);
  EXPECT_NE(run("simplify " + sphere_file() + " " + out + " --faces 10 --max-turn 120").exit_code, 0);
  EXPECT_NE(run("simplify /nonexistent/x.ply " + out + " --faces 10").exit_code, 0);
  for (const char* bad : {"gloss=1", "normal", "normal=-1", "uv=x", "color=1e999"}) {
    const CliRun r = run("simplify " + sphere_file() + " " + out + " --faces 10 --attribute-weight " + bad);
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_NE(r.out.find("--attribute-weight"), std::string::npos) << r.out;
  }
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(run("simplify " + sphere_file() + " " + out + " --faces 10 --attribute-weight normal=0.5,uv=2 "
                "--attribute-weight color=0")
                .exit_code,
            0);
}

namespace {

// By default the normal and colour weights grow to the spacing of the target's faces
// (src/spacing_weights.h); a weight of that kind given alone is the weight, as KIND-spacing=0
// makes it, and --json says which weight the run used. `floor` and `factor`: the defaults.
void expect_a_given_weight_is_used(const Mesh& mesh, const std::string& kind, const std::string& floor,
                                   const std::string& factor, const std::string& faces) {
  const std::string dir = test::temp_dir();
  const std::string in = dir + "/cli_" + kind + ".ply", out = dir + "/cli_" + kind + "_out.ply";
  save_mesh(in, mesh);
  const auto simplified = [&](const std::string& args) {
    EXPECT_EQ(run("simplify " + in + " " + out + " --faces " + faces + " --quiet " + args).exit_code, 0)
        << args;
    return load_mesh(out).positions;
  };
  const std::string weight = "--attribute-weight " + kind + "=",
                    spacing = "--attribute-weight " + kind + "-spacing=";
  const std::vector<double> by_default = simplified(""), fixed = simplified(weight + floor);
  EXPECT_NE(by_default, fixed);
  EXPECT_EQ(fixed, simplified(spacing + "0"));
  EXPECT_EQ(by_default, simplified(spacing + factor + "," + kind + "=" + floor));
  const CliRun r = run("simplify " + in + " " + out + " --faces " + faces + " --json " + weight + "0.25");
  EXPECT_NE(r.out.find("\"" + kind + "_weight\":0.25,"), std::string::npos) << r.out;
}

}  // namespace

TEST(CliSimplify, AGivenNormalWeightIsUsedAsItIs) {
  expect_a_given_weight_is_used(test::uv_sphere(30, 60), "normal", "0.01", "1", "300");
}

TEST(CliSimplify, AGivenColourWeightIsUsedAsItIs) {
  Mesh sphere = test::uv_sphere(20, 40);  // with normals, as above, and colours of no pattern
  std::vector<double> rgb(3 * sphere.vertex_count());
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = double((i * 7919) % 101) / 100.0;
  sphere.attributes.push_back({"COLOR_0", AttributeKind::Color, 3, rgb});
  expect_a_given_weight_is_used(sphere, "color", "0.1", "3", "150");
}

TEST(CliSimplify, HelpDocumentsEveryOption) {
  CliRun r = run("simplify --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* opt :
       {"--faces", "--ratio", "--vertices", "--max-error", "--max-error-rel", "--threshold",
        "--threshold-rel", "--weighting", "--placement", "--boundary-weight", "--lock-border", "--inversion",
        "--max-turn", "--allow-non-manifold", "--weld", "--json", "--quiet", "--force", "--double",
        "--refit", "--refit-rounds", "--record"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
  r = run("refit --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* opt : {"--rounds", "--lock-border", "--max-turn", "--threads", "--ascii", "--double", "--json",
                          "--quiet", "--force"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << "refit " << opt;
}

}  // namespace

// `qem generate --attributes`: the same sphere with unit normals and a UV map whose seam splits
// positions into wedges, and nothing else changed: same faces, same positions once welded.
TEST(CliGenerate, AttributesAddNormalsAndASeamedUvMap) {
  const std::string plain = test::temp_dir() + "/gen_plain.ply", attr = test::temp_dir() + "/gen_attr.ply";
  ASSERT_EQ(run("generate sphere --faces 1000 " + plain).exit_code, 0);
  CliRun r = run("generate sphere --faces 1000 --attributes " + attr);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const Mesh p = load_mesh(plain), a = load_mesh(attr);
  ASSERT_EQ(a.face_count(), p.face_count());
  const VertexAttribute* uv = a.find_attribute(AttributeKind::TexCoord);
  const VertexAttribute* n = a.find_attribute(AttributeKind::Normal);
  ASSERT_NE(uv, nullptr);
  ASSERT_NE(n, nullptr);
  EXPECT_GT(a.vertex_count(), p.vertex_count()) << "no vertex split at the seam";
  for (std::size_t v = 0; v < a.vertex_count(); ++v) {
    const double* nv = &n->values[3 * v];
    EXPECT_NEAR(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2], 1.0, 1e-5);  // PLY stores floats
  }
  // Each face's corners are the plain sphere's, and its UVs span less than half the map (no face
  // stretched across the seam).
  for (std::size_t f = 0; f < a.face_count(); ++f) {
    double lo = 2, hi = -1;
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(a.positions[3 * a.indices[3 * f + k] + c], p.positions[3 * p.indices[3 * f + k] + c], 1e-6);
      const double u = uv->values[2 * a.indices[3 * f + k]];
      lo = std::min(lo, u), hi = std::max(hi, u);
    }
    EXPECT_LT(hi - lo, 0.5) << "face " << f;
  }
}
