// Forgetting (SimplifyOptions::forget): the quadrics renewed from the current faces as the faces
// fall. What it must keep: one sequence of contractions for every target (records replay), the
// same output for any thread count, whole quadrics where an error bound needs them, the wedges'
// rules when attributes forget too, and a lower mean error than GH97's remembering quadrics on a
// real scan.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "qem/error.h"
#include "qem/io.h"
#include "qem/measure.h"
#include "qem/progressive.h"
#include "qem/simplify.h"
#include "mesh_checks.h"
#include "test_meshes.h"

using namespace qem;

namespace {

double ripples(double x, double y) { return 0.08 * std::sin(9 * x) * std::cos(7 * y) + 0.03 * std::sin(23 * x * y); }

// Passes all the way by default (no greedy tail), so the quadrics are renewed many times.
SimplifyOptions forgetting(std::size_t faces, double forget, std::size_t greedy_below = 0) {
  SimplifyOptions o;
  o.target_faces = faces;
  o.greedy_below_faces = greedy_below;
  o.forget = forget;
  return o;
}

TEST(Forget, ChangesTheRunAndKeepsItValid) {
  const Mesh in = test::height_field(60, ripples);  // open: its border planes are renewed too
  const SimplifyResult remember = simplify(in, forgetting(700, 0)), forget = simplify(in, forgetting(700, 0.85));
  EXPECT_NE(remember.mesh.positions, forget.mesh.positions);
  EXPECT_LE(forget.mesh.face_count(), 700u);
  EXPECT_GE(forget.mesh.face_count(), 690u);
  EXPECT_EQ(test::validity_problem(forget.mesh), "");
  // Exact borders hold under renewed quadrics too: every border vertex stays on the square's sides.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  const std::vector<std::uint32_t>& t = forget.mesh.indices;
  for (std::size_t i = 0; i < t.size(); i += 3)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[i + k], b = t[i + (k + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  std::size_t border_edges = 0;
  for (const auto& [edge, count] : uses) {
    if (count != 1) continue;
    ++border_edges;
    for (std::uint32_t v : {edge.first, edge.second}) {
      const double x = forget.mesh.positions[3 * v], y = forget.mesh.positions[3 * v + 1];
      EXPECT_TRUE(x == 0 || x == 1 || y == 0 || y == 1) << "border vertex " << v << " at " << x << ", " << y;
    }
  }
  EXPECT_GE(border_edges, 4u);
}

TEST(Forget, SameOutputForAnyThreadCount) {
  const Mesh in = test::height_field(90, ripples);
  for (std::size_t greedy_below : {0u, 6000u}) {  // passes only; renewals in the greedy tail too
    SCOPED_TRACE(greedy_below);
    SimplifyOptions one = forgetting(1500, 0.85, greedy_below), two = one, five = one;
    one.threads = 1, two.threads = 2, five.threads = 5;
    const SimplifyResult a = simplify(in, one), b = simplify(in, two), c = simplify(in, five);
    EXPECT_EQ(a.mesh.indices, b.mesh.indices);
    EXPECT_EQ(a.mesh.positions, b.mesh.positions);
    EXPECT_EQ(a.mesh.indices, c.mesh.indices);
    EXPECT_EQ(a.mesh.positions, c.mesh.positions);
  }
}

// The schedule follows the face count, not the target: the record of one run replays to what a
// direct run to any target gives.
TEST(Forget, RecordReplaysToDirectRuns) {
  const Mesh in = test::height_field(50, ripples);
  for (std::size_t greedy_below : {0u, 3000u}) {  // passes only; renewals in the greedy tail too
    SCOPED_TRACE(greedy_below);
    SimplifyOptions o = forgetting(60, 0.85, greedy_below);
    ContractionRecorder recorder;
    simplify(in, o, &recorder);
    const Record rec = make_record(in, recorder.log);
    for (std::size_t target : {4000u, 2500u, 900u, 300u, 60u}) {
      SCOPED_TRACE(target);
      o.target_faces = target;
      const SimplifyResult direct = simplify(in, o);
      const Mesh replayed = replay(rec, target);
      EXPECT_EQ(replayed.indices, direct.mesh.indices);
      EXPECT_EQ(replayed.positions, direct.mesh.positions);
    }
  }
}

// An error limit bounds the distance to the input only with whole quadrics; the wedges' attribute
// quadrics remember unless forget_attributes asks. In both cases the factor alone changes nothing.
TEST(Forget, OffUnderAnErrorLimitAndWithAttributesUnlessAsked) {
  const Mesh terrain = test::height_field(60, ripples);
  SimplifyOptions limited;
  limited.max_error = 0.002, limited.max_error_is_relative = true, limited.greedy_below_faces = 0;
  SimplifyOptions limited_forget = limited;
  limited_forget.forget = 0.85;
  const SimplifyResult a = simplify(terrain, limited), b = simplify(terrain, limited_forget);
  EXPECT_LT(a.mesh.face_count(), terrain.face_count() / 4);
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  EXPECT_EQ(a.mesh.indices, b.mesh.indices);

  const Mesh sphere = test::uv_sphere(40, 80);
  const SimplifyResult c = simplify(sphere, forgetting(500, 0)), d = simplify(sphere, forgetting(500, 0.85));
  EXPECT_EQ(c.mesh.positions, d.mesh.positions);
  EXPECT_EQ(c.mesh.indices, d.mesh.indices);
  SimplifyOptions asked = forgetting(500, 0.85);
  asked.forget_attributes = true;
  EXPECT_NE(simplify(sphere, asked).mesh.positions, c.mesh.positions);
}

// Attributes that never vary have no error to shift, so such a mesh forgets by default: faces'
// materials alone (carried through the core as a constant attribute), or a constant colour. Each
// run equals the one that asks for forget_attributes and differs from GH97's remembering run, and
// the materials stay apart.
TEST(Forget, ConstantAttributesAndMaterialsAloneForget) {
  Mesh materials = test::uv_sphere(40, 80);
  materials.attributes.clear();
  for (std::size_t f = 0; f < materials.face_count(); ++f) {
    const std::uint32_t* t = &materials.indices[3 * f];
    const double z = materials.positions[3 * t[0] + 2] + materials.positions[3 * t[1] + 2] +
                     materials.positions[3 * t[2] + 2];
    materials.face_materials.push_back(z > 0 ? 1 : 0);
  }
  Mesh constant = test::uv_sphere(40, 80);
  constant.attributes = {{"COLOR_0", AttributeKind::Color, 3, {}}};
  for (std::size_t v = 0; v < constant.vertex_count(); ++v)
    constant.attributes[0].values.insert(constant.attributes[0].values.end(), {0.2, 0.5, 0.9});
  for (const Mesh* in : {&materials, &constant}) {
    SimplifyOptions asked = forgetting(600, 0.85);
    asked.forget_attributes = true;
    const SimplifyResult remember = simplify(*in, forgetting(600, 0)),
                         by_default = simplify(*in, forgetting(600, 0.85)), forget = simplify(*in, asked);
    EXPECT_NE(by_default.mesh.positions, remember.mesh.positions);
    EXPECT_EQ(by_default.mesh.positions, forget.mesh.positions);
    EXPECT_EQ(by_default.mesh.indices, forget.mesh.indices);
    EXPECT_EQ(test::open_edges_welded(by_default.mesh), 0u) << "a crack opened";
    if (in == &materials) {
      ASSERT_EQ(by_default.mesh.face_materials.size(), by_default.mesh.face_count());
      EXPECT_TRUE(by_default.mesh.attributes.empty());
      for (std::size_t f = 0; f < by_default.mesh.face_count(); ++f)  // each face keeps its side
        EXPECT_EQ(by_default.mesh.face_materials[f], materials.face_materials[by_default.face_source[f]]);
    }
  }
}

// With attributes, the wedges' quadrics and the seam planes are renewed with the positions': the
// rules of the wedges still hold (seams closed and on their line, UVs in the chart, unit normals),
// in the passes and in the greedy order, with the same output for any thread count.
TEST(Forget, WithAttributesKeepsSeamsClosedOnAnyThreadCount) {
  const Mesh in = test::uv_sphere(40, 80);
  ASSERT_EQ(test::open_edges_welded(in), 0u);
  for (std::size_t greedy_below : {std::size_t(0), std::size_t(3000)}) {
    SCOPED_TRACE(greedy_below);
    std::vector<double> first;
    for (unsigned threads : {1u, 3u}) {
      SimplifyOptions o = forgetting(720, 0.85, greedy_below);
      o.forget_attributes = true;
      o.threads = threads;
      const SimplifyResult r = simplify(in, o);
      EXPECT_LE(r.mesh.face_count(), 720u);
      EXPECT_EQ(test::open_edges_welded(r.mesh), 0u) << "a crack opened";
      const VertexAttribute& uv = test::attribute(r.mesh, AttributeKind::TexCoord);
      const VertexAttribute& n = test::attribute(r.mesh, AttributeKind::Normal);
      for (std::size_t v = 0; v < r.mesh.vertex_count(); ++v) {
        const double u = uv.values[2 * v], su = in.attributes[0].values[2 * r.vertex_source[v]];
        EXPECT_GE(u, -1e-9);
        EXPECT_LE(u, 1 + 1e-9);
        if (su == 0 || su == 1) {
          EXPECT_EQ(r.mesh.positions[3 * v + 1], 0.0) << "seam vertex " << v << " left the seam";
          EXPECT_EQ(u, su);
        }
        EXPECT_NEAR(std::hypot(n.values[3 * v], n.values[3 * v + 1], n.values[3 * v + 2]), 1.0, 1e-12);
      }
      if (first.empty()) first = r.mesh.positions;
      else EXPECT_EQ(r.mesh.positions, first) << "differs on " << threads << " threads";
    }
  }
}

// The command line's spelling: --forget-attributes, without which a mesh with attributes keeps
// its quadrics whatever --forget says.
TEST(Forget, CommandLineAsksForAttributes) {
  const std::string dir = test::temp_dir(), in = dir + "/sphere.obj";
  save_mesh(in, test::uv_sphere(40, 80));
  const auto made = [&](const std::string& name, const std::string& flags) {
    EXPECT_EQ(test::run_qem_quietly("simplify " + in + " " + dir + "/" + name + " --faces 720 --no-refit " + flags), 0);
    return test::slurp(dir + "/" + name);
  };
  const std::string plain = made("plain.obj", ""), remember = made("remember.obj", "--forget 0"),
                    asked = made("asked.obj", "--forget-attributes");
  ASSERT_FALSE(plain.empty());
  EXPECT_EQ(plain, remember);
  EXPECT_NE(asked, plain);
}

TEST(Forget, FactorOutOfRangeIsRefused) {
  const Mesh in = test::icosphere(2);
  for (double bad : {-0.1, 1.0, 1.5, std::nan("")}) {
    SCOPED_TRACE(bad);
    EXPECT_THROW(simplify(in, forgetting(50, bad)), Error);
  }
}

// The reason it exists: on a scan, renewed quadrics rank the late contractions by what they do to
// the current surface and give a lower mean distance (E, GH97 §6.1) at the same face count.
TEST(Forget, LowersTheMeanErrorOnTheBunny) {
  const std::string path = test::shared_data("gh_bunny_zipper.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  const Mesh in = load_mesh(path);
  MeasureOptions m;
  m.samples = 200000;
  SimplifyOptions o;
  o.target_ratio = 0.1;
  SimplifyOptions f = o;
  f.forget = 0.85;
  const double remember = measure(in, simplify(in, o).mesh, m).E, forget = measure(in, simplify(in, f).mesh, m).E;
  EXPECT_LT(forget, 0.9 * remember);
}

// And with attributes, asked for: a textured scan's mean error falls too (spot.obj at 10 %, whose
// UV seams split its vertices).
TEST(Forget, WithAttributesLowersTheMeanErrorOnATexturedModel) {
  const std::string path = test::shared_data("spot.obj");
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  const Mesh in = load_mesh(path);
  ASSERT_FALSE(in.attributes.empty());
  MeasureOptions m;
  m.samples = 200000;
  SimplifyOptions o;
  o.target_ratio = 0.1;
  o.forget = 0.85;
  SimplifyOptions f = o;
  f.forget_attributes = true;
  const SimplifyResult remember = simplify(in, o), forget = simplify(in, f);
  EXPECT_EQ(test::open_edges_welded(forget.mesh), test::open_edges_welded(in));
  EXPECT_LT(measure(in, forget.mesh, m).E, 0.9 * measure(in, remember.mesh, m).E);
}

}  // namespace
