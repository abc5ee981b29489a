// The normal and colour weights from the spacing of the output's faces
// (AttributeWeights::normal_per_spacing and color_per_spacing, src/spacing_weights.h): their values,
// their independence of the model's scale and position, where they apply, and what they are for (a
// coarse output keeps small, sharply turning parts: the Duck's beak; a sphere of random colours keeps
// its colours at half its faces).
#include "spacing_weights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "qem/io.h"
#include "qem/measure.h"
#include "qem/simplify.h"
#include "test_meshes.h"

using namespace qem;

namespace {

// A unit square of two faces in z = 0 (area 1, box diagonal sqrt 2), with normals and colours when asked.
Mesh square(bool normals, bool colours = false) {
  Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  m.indices = {0, 1, 2, 0, 2, 3};
  if (normals)
    m.attributes.push_back({"NORMAL", AttributeKind::Normal, 3, {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}});
  if (colours)
    m.attributes.push_back({"COLOR_0", AttributeKind::Color, 3, {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1}});
  return m;
}

}  // namespace

TEST(NormalWeight, IsTheSpacingOfTheTargetsFacesInDiagonals) {
  SimplifyOptions o;
  // 2 faces on an area of 1: a spacing of sqrt(1 / 2), over the diagonal sqrt(2): 0.5.
  EXPECT_NEAR(with_spacing_weights(square(true), o, 2).attribute_weights.normal, 0.5, 1e-12);
  EXPECT_NEAR(with_spacing_weights(square(true), o, 200).attribute_weights.normal, 0.05, 1e-12);
  // Finer than the floor: the floor. No target: the weight as it was.
  EXPECT_EQ(with_spacing_weights(square(true), o, 1e6).attribute_weights.normal, o.attribute_weights.normal);
  EXPECT_EQ(with_spacing_weights(square(true), o, 0).attribute_weights.normal, o.attribute_weights.normal);
  // The factor scales it; resolved, it is not applied again.
  o.attribute_weights.normal_per_spacing = 2;
  const SimplifyOptions resolved = with_spacing_weights(square(true), o, 2);
  EXPECT_NEAR(resolved.attribute_weights.normal, 1.0, 1e-12);
  EXPECT_EQ(resolved.attribute_weights.normal_per_spacing, 0);
  EXPECT_FALSE(spacing_weights_unresolved(square(true), resolved));
  // Only for a mesh with normals.
  EXPECT_TRUE(spacing_weights_unresolved(square(true), o));
  EXPECT_FALSE(spacing_weights_unresolved(square(false), o));
}

TEST(NormalWeight, DoesNotDependOnTheModelsScaleOrPosition) {
  const Mesh in = test::uv_sphere(20, 40);
  SimplifyOptions o;
  o.target_faces = 150;
  const double w = with_spacing_weights(in, o).attribute_weights.normal;
  EXPECT_GT(w, 0.05);  // the sphere's area 4 pi, over 150 faces, in diagonals of 2 sqrt(3)
  const double moved =
      with_spacing_weights(test::transformed(in, 1e4, -3e5, 7, 1e3), o).attribute_weights.normal;
  EXPECT_NEAR(moved, w, 1e-9 * w);
}

TEST(NormalWeight, TheTargetAsTheCoreResolvesIt) {
  const Mesh in = square(true);
  SimplifyOptions o;
  o.target_ratio = 0.5;
  EXPECT_EQ(asked_faces(in, o), 1);
  o.target_faces = 2;  // the larger of a face and a ratio target
  EXPECT_EQ(asked_faces(in, o), 2);
  SimplifyOptions v;
  v.target_vertices = 10;  // a vertex target: twice as many faces
  EXPECT_EQ(asked_faces(in, v), 20);
  EXPECT_EQ(asked_faces(in, SimplifyOptions{}), 0);
}

TEST(NormalWeight, SimplifyWeighsTheNormalsAtTheOutputsSpacing) {
  // The run with the default options is the run with the resolved weight given, byte for byte, and
  // not the run with the fixed weight: simplify resolves it once, before anything else.
  const Mesh in = test::uv_sphere(30, 60);
  SimplifyOptions o;
  o.target_faces = 300;
  SimplifyOptions given = o;
  given.attribute_weights.normal = with_spacing_weights(in, o).attribute_weights.normal;
  given.attribute_weights.normal_per_spacing = 0;
  SimplifyOptions fixed = o;
  fixed.attribute_weights.normal_per_spacing = 0;
  const SimplifyResult by_default = simplify(in, o), resolved = simplify(in, given),
                       old = simplify(in, fixed);
  EXPECT_EQ(by_default.mesh.positions, resolved.mesh.positions);
  EXPECT_EQ(by_default.mesh.indices, resolved.mesh.indices);
  EXPECT_NE(by_default.mesh.positions, old.mesh.positions);
  // The result says which weight it used; a mesh without normals, none.
  EXPECT_EQ(by_default.normal_weight, given.attribute_weights.normal);
  EXPECT_EQ(old.normal_weight, o.attribute_weights.normal);
  EXPECT_EQ(simplify(test::icosphere(3), o).normal_weight, 0);
}

TEST(NormalWeight, TheDucksBeakKeepsItsNormalsAtATenth) {
  // Duck.glb to 10 %: with the fixed weight (0.01) the mouth's slit and the eyes, small areas of
  // sharply turning normals, were flattened: 9.6 degrees RMS against meshoptimizer's 6.8 (the
  // issue's attribute table, docs/attributes.md). With the weight of a 10 % output's spacing (0.05),
  // 6.3 degrees, at a geometric error still a third of meshoptimizer's.
  const std::string path = test::shared_data("Duck.glb");
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  const Mesh in = load_mesh(path);
  SimplifyOptions o;
  o.target_ratio = 0.1;
  o.refit_rounds = 0, o.far_repair = false;  // as the command line with normals and UVs: no refit
  SimplifyOptions fixed = o;
  fixed.attribute_weights.normal_per_spacing = 0;
  MeasureOptions m;
  m.samples = 200000;
  const MeasureResult now = measure(in, simplify(in, o).mesh, m),
                      before = measure(in, simplify(in, fixed).mesh, m);
  ASSERT_TRUE(now.normal_rms_deg && before.normal_rms_deg);
  std::printf("Duck to 10 %%: normals %.2f degrees (fixed weight %.2f), rms distance %.3g (%.3g)\n",
              *now.normal_rms_deg, *before.normal_rms_deg, now.rms_rel, before.rms_rel);
  EXPECT_LT(*now.normal_rms_deg, 7.0);
  EXPECT_GT(*before.normal_rms_deg, 8.5);
  EXPECT_LT(now.rms, 2 * before.rms);  // the geometry pays a little, not a lot
}

TEST(ColorWeight, IsThreeSpacingsUpToTheCap) {
  SimplifyOptions o;
  const Mesh in = square(false, true);
  // 200 faces: a spacing of 0.05 diagonals, three of them 0.15; 2 faces: 1.5, held at the cap.
  EXPECT_NEAR(with_spacing_weights(in, o, 200).attribute_weights.color, 0.15, 1e-12);
  EXPECT_EQ(with_spacing_weights(in, o, 2).attribute_weights.color, o.attribute_weights.color_spacing_cap);
  // Finer than the floor: the floor; no target: as it was. The normal weight has its own factor.
  EXPECT_EQ(with_spacing_weights(in, o, 1e6).attribute_weights.color, o.attribute_weights.color);
  EXPECT_EQ(with_spacing_weights(in, o, 0).attribute_weights.color, o.attribute_weights.color);
  SimplifyOptions colour_only = o;
  colour_only.attribute_weights.normal_per_spacing = 0;
  EXPECT_EQ(with_spacing_weights(in, colour_only, 2).attribute_weights.normal, o.attribute_weights.normal);
  // A floor above the cap stays the weight.
  SimplifyOptions high = o;
  high.attribute_weights.color = 0.7;
  EXPECT_EQ(with_spacing_weights(in, high, 2).attribute_weights.color, 0.7);
  // Only for a mesh with colours; resolved, not applied again.
  EXPECT_TRUE(spacing_weights_unresolved(in, o));
  EXPECT_FALSE(spacing_weights_unresolved(in, with_spacing_weights(in, o, 200)));
  o.attribute_weights.normal_per_spacing = 0;
  EXPECT_FALSE(spacing_weights_unresolved(square(true), o));
}

TEST(ColorWeight, TheResultSaysWhichWeightTheRunUsed) {
  Mesh in = test::uv_sphere(20, 40);
  std::vector<double> rgb(3 * in.vertex_count());
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = double((i * 7919) % 101) / 100.0;
  in.attributes.push_back({"COLOR_0", AttributeKind::Color, 3, rgb});
  SimplifyOptions o;
  o.target_faces = 150;
  const double expected = with_spacing_weights(in, o).attribute_weights.color;
  EXPECT_GT(expected, o.attribute_weights.color);
  EXPECT_EQ(simplify(in, o).color_weight, expected);
  SimplifyOptions fixed = o;
  fixed.attribute_weights.color_per_spacing = 0;
  EXPECT_EQ(simplify(in, fixed).color_weight, o.attribute_weights.color);
  EXPECT_EQ(simplify(test::icosphere(3), o).color_weight, 0);
}

TEST(ColorWeight, ASphereOfRandomColoursKeepsThemAtHalfItsFaces) {
  // tiny_sphere_vcolor.ply (224 faces, a random colour at each vertex) to 50 %: with the fixed weight
  // (0.1) the geometry chose the contractions and the colour RMS was 0.043 against meshoptimizer's
  // 0.025 (the attribute table); with the weight of the output's spacing (0.29), 0.019.
  const std::string path = test::shared_data("tiny_sphere_vcolor.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  const Mesh in = load_mesh(path);
  SimplifyOptions o;
  o.target_ratio = 0.5;
  SimplifyOptions fixed = o;
  fixed.attribute_weights.color_per_spacing = 0;
  MeasureOptions m;
  m.samples = 200000;
  const MeasureResult now = measure(in, simplify(in, o).mesh, m),
                      before = measure(in, simplify(in, fixed).mesh, m);
  ASSERT_TRUE(now.color_rms && before.color_rms);
  std::printf("tiny sphere to 50 %%: colour rms %.4f (fixed weight %.4f), rms distance %.3g (%.3g)\n",
              *now.color_rms, *before.color_rms, now.rms_rel, before.rms_rel);
  EXPECT_LT(*now.color_rms, 0.025);
  EXPECT_GT(*before.color_rms, 0.035);
}
