// Tests of the refit (qem/refit.h, Hoppe et al. 1993 §4.2): it recovers a surface it can represent
// exactly, lowers the GH97 §6.1 error of a real simplification, never folds a face over, honours
// a locked border, and is deterministic and independent of scale, position and thread count.
#include "qem/refit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "measure/bvh.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/measure.h"
#include "qem/simplify.h"
#include "refit/refit_after_simplify.h"
#include "refit/refit_points.h"
#include "test_meshes.h"

namespace qem {
namespace {

double waves(double x, double y) { return 0.1 * std::sin(6 * x) * std::cos(5 * y); }

/// A coarse grid over the unit square with its interior lifted off the plane z = 0.
Mesh lifted_coarse_grid() {
  Mesh m = test::grid(4);
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    const double x = m.positions[3 * v], y = m.positions[3 * v + 1];
    if (x > 0 && x < 1 && y > 0 && y < 1) m.positions[3 * v + 2] = 0.05 * (1 + x * y);
  }
  return m;
}

SimplifyResult coarse_sphere(int faces) {
  SimplifyOptions o;
  o.target_faces = std::size_t(faces);
  return simplify(test::icosphere(4), o);
}

double face_turn_degrees(const Mesh& a, const Mesh& b, std::size_t f) {
  auto normal = [f](const Mesh& m, double n[3]) {
    const std::uint32_t* t = &m.indices[3 * f];
    const double* p0 = &m.positions[3 * t[0]];
    const double* p1 = &m.positions[3 * t[1]];
    const double* p2 = &m.positions[3 * t[2]];
    const double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const double v[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    n[0] = u[1] * v[2] - u[2] * v[1], n[1] = u[2] * v[0] - u[0] * v[2], n[2] = u[0] * v[1] - u[1] * v[0];
  };
  double na[3], nb[3];
  normal(a, na), normal(b, nb);
  const double dot = na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2];
  const double len = std::sqrt((na[0] * na[0] + na[1] * na[1] + na[2] * na[2]) *
                               (nb[0] * nb[0] + nb[1] * nb[1] + nb[2] * nb[2]));
  return std::acos(std::clamp(dot / len, -1.0, 1.0)) * 180 / std::numbers::pi;
}

TEST(Refit, RecoversASurfaceTheFacesCanRepresent) {
  // The original is the plane z = 0 (a fine grid); the approximation's faces can lie in it exactly,
  // so the fit must bring every lifted vertex back down. The membrane on the displacement lets each
  // round take only part of the way here (the lift jumps at the border), so convergence is linear:
  // most of the way in the default 3 rounds, all of it in 40.
  const Mesh original = test::grid(40);
  Mesh approx = lifted_coarse_grid();
  const RefitResult r3 = refit(original, approx);
  EXPECT_GT(r3.rms_before, 0.01);
  EXPECT_EQ(r3.rounds, 3u);
  EXPECT_LT(r3.rms_after, 0.25 * r3.rms_before);
  approx = lifted_coarse_grid();
  RefitOptions many;
  many.rounds = 40;
  const RefitResult r = refit(original, approx, many);
  EXPECT_EQ(r.rounds, 40u);
  EXPECT_LT(r.rms_after, 1e-3 * r.rms_before);
  for (std::size_t v = 0; v < approx.vertex_count(); ++v)
    EXPECT_NEAR(approx.positions[3 * v + 2], 0, 1e-4) << v;
}

TEST(Refit, LowersTheErrorOfASimplification) {
  const Mesh original = test::icosphere(4);
  for (int faces : {60, 300}) {
    SCOPED_TRACE(faces);
    const Mesh before = coarse_sphere(faces).mesh;
    Mesh after = before;
    const RefitResult r = refit(original, after);
    EXPECT_LT(r.rms_after, 0.9 * r.rms_before);
    MeasureOptions m;
    m.samples = 200000;
    const double e_before = measure(original, before, m).E, e_after = measure(original, after, m).E;
    EXPECT_LT(e_after, 0.9 * e_before) << e_before << " -> " << e_after;
    ASSERT_EQ(after.indices, before.indices);  // connectivity untouched
  }
}

// The rounds after the first project each point only onto the faces around its face of the round
// before; the RMS they report must still be the true one, to the closest of all faces.
TEST(Refit, ReportedErrorIsTheDistanceToTheClosestOfAllFaces) {
  const Mesh original = test::height_field(40, waves);
  SimplifyOptions o;
  o.target_faces = 150;
  Mesh approx = simplify(original, o).mesh;
  const RefitResult r = refit(original, approx);
  ASSERT_GT(r.rounds, 1u);
  std::vector<double> corners;
  for (std::uint32_t v : approx.indices)
    corners.insert(corners.end(), &approx.positions[3 * v], &approx.positions[3 * v] + 3);
  const measure_detail::TriangleBvh tree(corners);
  const std::vector<double> area = refit_detail::vertex_areas(original);
  double sum = 0, total = 0;
  for (std::size_t v = 0; v < original.vertex_count(); ++v) {
    sum += area[v] * tree.closest(&original.positions[3 * v]).d2;
    total += area[v];
  }
  EXPECT_NEAR(r.rms_after, std::sqrt(sum / total), 1e-12 * r.rms_after);
}

TEST(Refit, AMeshThatFitsExactlyDoesNotMove) {
  const Mesh original = test::icosphere(2);
  Mesh approx = original;
  const RefitResult r = refit(original, approx);
  EXPECT_EQ(r.rms_before, 0);
  EXPECT_EQ(r.rounds, 0u);
  EXPECT_EQ(approx.positions, original.positions);  // bit for bit
}

TEST(Refit, NoFaceTurnsBeyondTheLimitInARound) {
  // A crude approximation of a wavy surface: the fit moves vertices a lot, and the limit holds
  // some of the moves back.
  const Mesh original = test::height_field(60, waves);
  Mesh before = test::grid(6);
  for (std::size_t v = 0; v < before.vertex_count(); ++v)
    before.positions[3 * v + 2] = 0.2 * ((v * 7) % 5) / 5.0;
  for (double limit : {10.0, 15.0}) {
    SCOPED_TRACE(limit);
    Mesh after = before;
    RefitOptions o;
    o.rounds = 1;
    o.max_normal_turn_degrees = limit;
    const RefitResult r = refit(original, after, o);
    ASSERT_EQ(r.rounds, 1u);
    EXPECT_GT(r.vertices_held, 0u);
    EXPECT_LT(r.rms_after, r.rms_before);
    for (std::size_t f = 0; f < after.face_count(); ++f)
      EXPECT_LE(face_turn_degrees(before, after, f), limit + 1e-9) << f;
  }
}

TEST(Refit, LockedBorderStaysPut) {
  const Mesh original = test::height_field(40, waves);
  Mesh approx = lifted_coarse_grid();
  for (std::size_t v = 0; v < approx.vertex_count(); ++v) approx.positions[3 * v + 2] += 0.03;  // border too
  const Mesh before = approx;
  RefitOptions o;
  o.lock_border = true;
  const RefitResult r = refit(original, approx, o);
  EXPECT_LT(r.rms_after, r.rms_before);
  std::size_t moved = 0;
  for (std::size_t v = 0; v < approx.vertex_count(); ++v) {
    const double x = before.positions[3 * v], y = before.positions[3 * v + 1];
    const bool border = x == 0 || x == 1 || y == 0 || y == 1;
    const bool same = approx.positions[3 * v] == before.positions[3 * v] &&
                      approx.positions[3 * v + 1] == before.positions[3 * v + 1] &&
                      approx.positions[3 * v + 2] == before.positions[3 * v + 2];
    if (border) {
      EXPECT_TRUE(same) << "border vertex " << v << " moved";
    }
    moved += !same;
  }
  EXPECT_EQ(moved, 9u);  // the 3 x 3 interior vertices
}

TEST(Refit, SameResultAtAnyScalePositionAndThreadCount) {
  const Mesh original = test::icosphere(4);
  const Mesh approx = coarse_sphere(200).mesh;
  RefitOptions one;
  one.threads = 1;
  Mesh a = approx;
  refit(original, a, one);
  RefitOptions three = one;
  three.threads = 3;
  Mesh b = approx;
  refit(original, b, three);
  EXPECT_EQ(a.positions, b.positions);  // bit for bit
  Mesh c = approx;
  refit(original, c, one);
  EXPECT_EQ(a.positions, c.positions);

  const double s = 1e3, o[3] = {2e4, -7e3, 5e2};
  Mesh moved = test::transformed(approx, s, o[0], o[1], o[2]);
  const RefitResult r = refit(test::transformed(original, s, o[0], o[1], o[2]), moved, one);
  EXPECT_GT(r.rounds, 0u);
  for (std::size_t i = 0; i < a.positions.size(); ++i)
    EXPECT_NEAR((moved.positions[i] - o[i % 3]) / s, a.positions[i], 1e-9) << i;
}

TEST(Refit, SeveralApproximationsAtOnceEqualOneByOne) {
  const Mesh original = test::icosphere(4);
  std::vector<Mesh> levels = {coarse_sphere(800).mesh, coarse_sphere(200).mesh, coarse_sphere(60).mesh};
  std::vector<Mesh> alone = levels;
  std::vector<RefitResult> expected;
  for (Mesh& m : alone) expected.push_back(refit(original, m));
  std::vector<Mesh*> pointers;
  for (Mesh& m : levels) pointers.push_back(&m);
  const std::vector<RefitResult> got = refit(original, pointers);
  ASSERT_EQ(got.size(), levels.size());
  for (std::size_t i = 0; i < levels.size(); ++i) {
    EXPECT_EQ(levels[i].positions, alone[i].positions) << i;  // bit for bit
    EXPECT_EQ(got[i].rms_before, expected[i].rms_before) << i;
    EXPECT_EQ(got[i].rms_after, expected[i].rms_after) << i;
    EXPECT_EQ(got[i].rounds, expected[i].rounds) << i;
    EXPECT_GT(got[i].rounds, 0u) << i;
  }
  EXPECT_TRUE(refit(original, std::span<Mesh* const>{}).empty());
}

TEST(Refit, BadInputIsAnError) {
  const Mesh original = test::icosphere(2);
  Mesh approx = test::icosphere(1);
  Mesh bad = original;
  bad.indices[5] = 9999;
  EXPECT_THROW(refit(bad, approx), Error);
  Mesh nan = approx;
  nan.positions[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(refit(original, nan), Error);
  RefitOptions o;
  o.max_normal_turn_degrees = 0;
  EXPECT_THROW(refit(original, approx, o), Error);
  Mesh empty;
  EXPECT_NO_THROW(refit(original, empty));  // nothing to fit: nothing happens
  // Several at once: a bad one is found before any other moves.
  Mesh first = coarse_sphere(60).mesh;
  const Mesh untouched = first;
  Mesh* both[] = {&first, &nan};
  EXPECT_THROW(refit(test::icosphere(4), both), Error);
  EXPECT_EQ(first.positions, untouched.positions);
}

TEST(Refit, SimplifyRefitsItsOutputWhenAsked) {
  // simplify(refit_rounds) is simplify, then refit against the input, in either overload.
  const Mesh input =
      test::concatenated(test::icosphere(4), test::transformed(test::height_field(20, waves), 1, 3, 0, 0));
  SimplifyOptions o;
  o.target_faces = 400;
  const SimplifyResult plain = simplify(input, o);
  o.refit_rounds = 2;
  const SimplifyResult fitted = simplify(input, o);
  Mesh expected = plain.mesh;
  const RefitResult r = refit(input, expected, refit_options_for(o));
  EXPECT_EQ(fitted.mesh.positions, expected.positions);
  EXPECT_EQ(fitted.mesh.indices, plain.mesh.indices);
  EXPECT_EQ(fitted.refit_rms_before, r.rms_before);
  EXPECT_EQ(fitted.refit_rms_after, r.rms_after);
  EXPECT_LT(fitted.refit_rms_after, fitted.refit_rms_before);
  EXPECT_EQ(fitted.refit_rounds, r.rounds);
  Mesh copy = input;
  const SimplifyResult consumed = simplify(std::move(copy), o);
  EXPECT_EQ(consumed.mesh.positions, fitted.mesh.positions);
}

TEST(Refit, SimplifysWalkFromTheContractionMapFindsTheTreesFaces) {
  // simplify's refit starts each input vertex's first search at the output vertex it was
  // contracted into, where qem::refit asks a tree: the same faces, so the same bytes, whatever
  // renamed the vertices on the way (renumbering between passes, chains of contractions in the
  // greedy order, joins of separate parts, several threads). A wrong map would start searches on
  // the wrong part of this two-part mesh.
  const Mesh input =
      test::concatenated(test::icosphere(5), test::transformed(test::height_field(40, waves), 1, 3, 0, 0));
  struct Case {
    const char* name;
    Scheme scheme;
    std::size_t greedy_below;
    double threshold;
    unsigned threads;
    double sample;
  };
  for (const Case& c :
       {Case{"passes", Scheme::Passes, 0, 0, 1, 0}, Case{"passes, 4 threads", Scheme::Passes, 0, 0, 4, 0},
        Case{"greedy", Scheme::Greedy, 0, 0, 1, 0}, Case{"greedy tail", Scheme::Passes, 3000, 0, 2, 2},
        Case{"joins", Scheme::Passes, 0, 0.05, 2, 0}, Case{"sampled", Scheme::Passes, 0, 0, 2, 2}}) {
    SCOPED_TRACE(c.name);
    SimplifyOptions o;
    o.target_faces = 300;
    o.scheme = c.scheme;
    o.greedy_below_faces = c.greedy_below;
    o.threshold = c.threshold;
    o.threshold_is_relative = true;
    o.threads = c.threads;
    const SimplifyResult plain = simplify(input, o);
    o.refit_rounds = 2;
    o.refit_points_per_vertex = c.sample;
    const SimplifyResult fitted = simplify(input, o);
    Mesh expected = plain.mesh;
    const RefitResult r = refit(input, expected, refit_options_for(o));
    EXPECT_EQ(fitted.refit_rms_before, r.rms_before);
    EXPECT_EQ(fitted.mesh.positions, expected.positions);
    EXPECT_GT(fitted.refit_rounds, 0u);
  }
}

TEST(Refit, ClosestFacesAfterTheRefitAreTheTrees) {
  // What the far-place repair starts from (refit_to_points' closest_faces): when the refit fitted
  // a sample, every point's face is as close as the tree's answer on the refitted output (walked
  // from the vertex the point went into), on a mesh of two parts. When it fitted every point, its
  // last round is kept on the bound (each point on its face of the projection before): those
  // faces, handed on, are nearly all the closest, and the reported error is their distances',
  // at least the true one.
  const Mesh input =
      test::concatenated(test::icosphere(5), test::transformed(test::height_field(40, waves), 1, 3, 0, 0));
  for (const double sample : {0.0, 2.0}) {
    SCOPED_TRACE(sample);
    SimplifyOptions o;
    o.target_faces = 300;
    o.threads = 2;
    o.map_input_vertices = true;
    const SimplifyResult plain = simplify(input, o);
    o.refit_rounds = 2;
    o.refit_points_per_vertex = sample;
    const refit_detail::FitPoints points(input.positions, refit_detail::vertex_areas(input));
    Mesh mesh = plain.mesh;
    std::vector<std::uint32_t> closest;
    const RefitResult r = refit_detail::refit_to_points(points, mesh, refit_options_for(o),
                                                        plain.output_vertex_of_input, nullptr, &closest);
    EXPECT_GT(r.rounds, 0u);
    ASSERT_EQ(closest.size(), points.weight.size());
    std::vector<double> corners;
    for (std::uint32_t v : mesh.indices) {
      const Vec3 q = points.frame().to_frame(
          {mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]});
      corners.insert(corners.end(), {q.x, q.y, q.z});
    }
    const measure_detail::TriangleBvh tree(corners);
    std::size_t exact = 0;
    double on_faces = 0, true_energy = 0;
    for (std::size_t j = 0; j < closest.size(); ++j) {
      ASSERT_LT(closest[j], mesh.face_count());
      const double* p = &points.position[3 * j];
      const double d2 = tree.triangle_d2(p, closest[j]), least = tree.closest(p).d2;
      if (sample > 0) {
        EXPECT_NEAR(d2, least, 1e-15) << "point " << j;
      }
      exact += d2 <= least + 1e-15;
      on_faces += points.weight[j] * d2, true_energy += points.weight[j] * least;
    }
    if (sample == 0) {
      EXPECT_GT(double(exact), 0.95 * double(closest.size()));
      const double scale = points.frame().scale;
      EXPECT_NEAR(r.rms_after, std::sqrt(on_faces / points.total_weight) * scale, 1e-9 * r.rms_after);
      EXPECT_GE(r.rms_after, std::sqrt(true_energy / points.total_weight) * scale * (1 - 1e-12));
    }
  }
}

TEST(Refit, ThinnedPointsKeepTheFrameAndTheTotalWeight) {
  const Mesh original = test::icosphere(3);
  const std::vector<double> weights = refit_detail::vertex_areas(original);
  const refit_detail::FitPoints all(original.positions, weights);
  for (std::size_t group : {2, 3, 7}) {
    SCOPED_TRACE(group);
    const refit_detail::FitPoints few = all.thinned(group);
    ASSERT_EQ(few.weight.size(), (all.weight.size() + group - 1) / group);
    ASSERT_EQ(few.order.size(), few.weight.size());
    EXPECT_NEAR(few.total_weight, all.total_weight, 1e-12 * all.total_weight);
    EXPECT_EQ(few.diag, all.diag);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(few.centre[k], all.centre[k]);
    // Each kept point is one of the originals, and together they carry every run's weight.
    double sum = 0;
    for (std::size_t j = 0; j < few.weight.size(); ++j) {
      bool found = false;
      for (std::size_t i = 0; i < all.weight.size() && !found; ++i)
        found = all.position[3 * i] == few.position[3 * j] &&
                all.position[3 * i + 1] == few.position[3 * j + 1] &&
                all.position[3 * i + 2] == few.position[3 * j + 2];
      EXPECT_TRUE(found) << j;
      EXPECT_GT(few.weight[j], 0);
      sum += few.weight[j];
    }
    EXPECT_NEAR(sum, all.total_weight, 1e-12 * all.total_weight);
  }
}

TEST(Refit, AFitToSampledPointsKeepsMostOfTheGain) {
  const Mesh original = test::icosphere(5);  // 10242 vertices
  const Mesh before = coarse_sphere(300).mesh;
  RefitOptions sampled;
  sampled.points_per_vertex = 4;  // about 600 of the 10242 points
  sampled.threads = 1;
  Mesh a = before;
  const RefitResult r = refit(original, a, sampled);
  EXPECT_GT(r.rounds, 0u);
  EXPECT_LT(r.rms_after, 0.9 * r.rms_before);
  Mesh full = before;
  refit(original, full);
  EXPECT_NE(a.positions, full.positions);  // the sample is in use
  MeasureOptions m;
  m.samples = 200000;
  const double e_before = measure(original, before, m).E, e_sampled = measure(original, a, m).E;
  const double e_full = measure(original, full, m).E;
  EXPECT_LT(e_sampled, 0.9 * e_before) << e_before << " -> " << e_sampled;
  // Most of the full fit's gain: at least 80 % of it.
  EXPECT_GT(e_before - e_sampled, 0.8 * (e_before - e_full)) << e_sampled << " full " << e_full;
  ASSERT_EQ(a.indices, before.indices);

  // Deterministic, for any thread count, scale and position.
  RefitOptions three = sampled;
  three.threads = 3;
  Mesh b = before;
  refit(original, b, three);
  EXPECT_EQ(a.positions, b.positions);
  const double s = 1e-3, o[3] = {-40, 7, 1e3};
  Mesh moved = test::transformed(before, s, o[0], o[1], o[2]);
  refit(test::transformed(original, s, o[0], o[1], o[2]), moved, sampled);
  for (std::size_t i = 0; i < a.positions.size(); ++i)
    EXPECT_NEAR((moved.positions[i] - o[i % 3]) / s, a.positions[i], 1e-9) << i;

  // A sample no smaller than half the original is the original itself.
  RefitOptions plenty;
  plenty.points_per_vertex = 1e6;
  Mesh c = before;
  refit(original, c, plenty);
  EXPECT_EQ(c.positions, full.positions);

  for (double bad :
       {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    RefitOptions o2;
    o2.points_per_vertex = bad;
    Mesh d = before;
    EXPECT_THROW(refit(original, d, o2), Error) << bad;
    SimplifyOptions so;
    so.target_faces = 300;
    so.refit_rounds = 1;
    so.refit_points_per_vertex = bad;
    EXPECT_THROW(simplify(original, so), Error) << bad;
  }
}

// --- the CLI ---------------------------------------------------------------------------------

using test::slurp;
int run(const std::string& args) { return test::run_qem_quietly(args); }

TEST(Refit, CliDefaultRefitFollowsTheReduction) {
  // The light refit raises E when each output vertex stands for only a few input vertices: none at
  // half the faces, one round on 2 points at a quarter, two rounds on 8 from a sixth down; a lod
  // chain refits each level as simplify does at that target.
  const std::string dir = test::temp_dir() + "/refit_by_reduction";
  std::filesystem::create_directories(dir);
  const std::string in = dir + "/in.obj";
  save_mesh(in, test::concatenated(test::icosphere(4),
                                   test::transformed(test::height_field(20, waves), 1, 3, 0, 0)));
  const std::size_t faces = load_mesh(in).face_count();
  const auto made = [&](const std::string& name, std::size_t target, const std::string& options) {
    EXPECT_EQ(run("simplify " + in + " " + dir + "/" + name + " --faces " + std::to_string(target) + " " + options), 0)
        << options;
    return slurp(dir + "/" + name);
  };
  const std::size_t half = faces / 2, quarter = faces / 4, tenth = faces / 10;
  const std::string d_half = made("d_half.obj", half, ""), d_quarter = made("d_quarter.obj", quarter, ""),
                    d_tenth = made("d_tenth.obj", tenth, "");
  EXPECT_TRUE(d_half == made("n_half.obj", half, "--no-refit")) << "half the faces: no refit";
  EXPECT_TRUE(d_quarter == made("o_quarter.obj", quarter, "--refit-rounds 1 --refit-sample 2"));
  EXPECT_NE(d_quarter, made("n_quarter.obj", quarter, "--no-refit"));
  EXPECT_TRUE(d_tenth == made("t_tenth.obj", tenth, "--refit-rounds 2 --refit-sample 8"));
  // Asked for, the rounds are made whatever the reduction.
  EXPECT_NE(made("a_half.obj", half, "--refit-rounds 2 --refit-sample 8"), d_half);
  ASSERT_EQ(run("lod " + in + " " + dir + "/lod --faces " + std::to_string(half) + "," + std::to_string(quarter) +
                "," + std::to_string(tenth) + " --format obj"),
            0);
  EXPECT_TRUE(slurp(dir + "/lod/in_lod0.obj") == d_half);
  EXPECT_TRUE(slurp(dir + "/lod/in_lod1.obj") == d_quarter);
  EXPECT_TRUE(slurp(dir + "/lod/in_lod2.obj") == d_tenth);
}

TEST(Refit, CliSimplifyRefitEqualsRefitCommandAndLodLevel) {
  const std::string dir = test::temp_dir() + "/refit_cli";
  std::filesystem::create_directories(dir);
  const std::string in = dir + "/in.obj";  // OBJ keeps doubles exactly, so files chain losslessly
  save_mesh(in, test::concatenated(test::icosphere(4),
                                   test::transformed(test::height_field(20, waves), 1, 3, 0, 0)));
  ASSERT_EQ(run("simplify " + in + " " + dir + "/fitted.obj --faces 500 --refit"), 0);
  ASSERT_EQ(run("simplify " + in + " " + dir + "/plain.obj --faces 500 --no-refit"), 0);
  ASSERT_EQ(
      run("simplify " + in + " " + dir + "/json.obj --faces 500 --refit --json > " + dir + "/line.json"), 0);
  const std::string line = slurp(dir + "/line.json");
  EXPECT_NE(line.find("\"refit_rounds\":3,"), std::string::npos) << line;
  EXPECT_NE(line.find("\"refit_rms_after\":"), std::string::npos) << line;
  // Exact borders (the default): simplify's refit does not move border vertices, as qem refit --lock-border.
  ASSERT_EQ(run("refit " + in + " " + dir + "/plain.obj " + dir + "/refitted.obj --lock-border"), 0);
  const std::string fitted = slurp(dir + "/fitted.obj");
  EXPECT_FALSE(fitted.empty());
  EXPECT_NE(fitted, slurp(dir + "/plain.obj"));
  // qem refit moves vertices only: simplify's flips after its refit are left out to compare.
  ASSERT_EQ(run("simplify " + in + " " + dir + "/unflipped.obj --faces 500 --refit --no-far-repair"), 0);
  EXPECT_NE(fitted, slurp(dir + "/unflipped.obj"));  // (the flips did something here)
  EXPECT_TRUE(slurp(dir + "/unflipped.obj") == slurp(dir + "/refitted.obj"))
      << "qem refit --lock-border differs from simplify --refit";
  ASSERT_EQ(run("simplify " + in + " " + dir + "/exact.obj --faces 500 --refit --exact-borders"), 0);
  EXPECT_TRUE(slurp(dir + "/exact.obj") == fitted) << "--exact-borders is not the default";
  // With GH97's penalty borders the refit moves border vertices too: qem refit without --lock-border.
  ASSERT_EQ(run("simplify " + in + " " + dir + "/penalty.obj --faces 500 --refit --penalty-borders --no-far-repair"), 0);
  ASSERT_EQ(run("simplify " + in + " " + dir + "/penalty_plain.obj --faces 500 --no-refit --penalty-borders"), 0);
  ASSERT_EQ(run("refit " + in + " " + dir + "/penalty_plain.obj " + dir + "/penalty_refitted.obj"), 0);
  EXPECT_NE(slurp(dir + "/penalty.obj"), fitted);
  EXPECT_TRUE(slurp(dir + "/penalty.obj") == slurp(dir + "/penalty_refitted.obj"))
      << "qem refit differs from simplify --refit --penalty-borders";
  ASSERT_EQ(run("lod " + in + " " + dir + "/lod --faces 2000,500 --format obj --refit"), 0);
  EXPECT_TRUE(fitted == slurp(dir + "/lod/in_lod1.obj")) << "lod --refit level differs from simplify --refit";
  ASSERT_EQ(run("simplify " + in + " " + dir + "/f2000.obj --faces 2000 --refit-rounds 3"), 0);
  EXPECT_TRUE(slurp(dir + "/f2000.obj") == slurp(dir + "/lod/in_lod0.obj"));
  // A record would replay the unrefitted contractions: the combination is refused, nothing written.
  EXPECT_NE(run("simplify " + in + " " + dir + "/rec.obj --faces 500 --refit --record " + dir +
                "/r.qrec 2>/dev/null"),
            0);
  EXPECT_FALSE(std::filesystem::exists(dir + "/rec.obj"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/r.qrec"));
  // Bad input: a clear error and no output.
  { std::ofstream(dir + "/bad.obj") << "v 0 0 0\nv 1 0 0\nf 1 2 7\n"; }
  EXPECT_NE(run("refit " + dir + "/bad.obj " + dir + "/plain.obj " + dir + "/x.obj 2>/dev/null"), 0);
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.obj"));
}

TEST(Refit, CliSampledRefitIsTheSameInSimplifyRefitAndLod) {
  const std::string dir = test::temp_dir() + "/refit_sample_cli";
  std::filesystem::create_directories(dir);
  const std::string in = dir + "/in.obj";
  save_mesh(in, test::icosphere(5));
  ASSERT_EQ(run("simplify " + in + " " + dir + "/sampled.obj --faces 400 --refit-sample 3"), 0);
  ASSERT_EQ(run("simplify " + in + " " + dir + "/full.obj --faces 400 --refit"), 0);
  ASSERT_EQ(run("simplify " + in + " " + dir + "/plain.obj --faces 400 --no-refit"), 0);
  ASSERT_EQ(run("refit " + in + " " + dir + "/plain.obj " + dir + "/refitted.obj --sample 3"), 0);
  ASSERT_EQ(run("lod " + in + " " + dir + "/lod --faces 400 --format obj --refit-sample 3"), 0);
  const std::string sampled = slurp(dir + "/sampled.obj");
  EXPECT_FALSE(sampled.empty());
  EXPECT_NE(sampled, slurp(dir + "/full.obj"));
  EXPECT_NE(sampled, slurp(dir + "/plain.obj"));
  ASSERT_EQ(run("simplify " + in + " " + dir + "/unflipped.obj --faces 400 --refit-sample 3 --no-far-repair"), 0);
  EXPECT_TRUE(slurp(dir + "/unflipped.obj") == slurp(dir + "/refitted.obj")) << "qem refit --sample differs from simplify";
  EXPECT_TRUE(sampled == slurp(dir + "/lod/in_lod0.obj")) << "lod --refit-sample differs from simplify";
  EXPECT_NE(run("simplify " + in + " " + dir + "/neg.obj --faces 400 --refit-sample -1 2>/dev/null"), 0);
  EXPECT_FALSE(std::filesystem::exists(dir + "/neg.obj"));
  EXPECT_NE(run("refit " + in + " " + dir + "/plain.obj " + dir + "/neg.obj --sample nan 2>/dev/null"), 0);
  EXPECT_FALSE(std::filesystem::exists(dir + "/neg.obj"));
}

TEST(Refit, CliDefaultIsALightRefitWithOptimalPlacementOnly) {
  const std::string dir = test::temp_dir() + "/refit_default_cli";
  std::filesystem::create_directories(dir);
  const std::string in = dir + "/in.obj";
  save_mesh(in, test::concatenated(test::icosphere(5),
                                   test::transformed(test::height_field(20, waves), 1, 3, 0, 0)));
  const auto made = [&](const std::string& name, const std::string& options) {
    EXPECT_EQ(run("simplify " + in + " " + dir + "/" + name + " --faces 600 " + options), 0) << options;
    return slurp(dir + "/" + name);
  };
  // The default is the light refit (below: it lowers the fit's error).
  const std::string fitted = made("default.obj", "");
  EXPECT_FALSE(fitted.empty());
  EXPECT_TRUE(fitted == made("light.obj", "--refit-rounds 2 --refit-sample 8"));
  const std::string plain = made("plain.obj", "--no-refit --forget 0");
  EXPECT_NE(fitted, plain);
  const auto library = [&](double forget) {
    SimplifyOptions o;
    o.target_faces = 600;
    o.forget = forget;
    return simplify(load_mesh(in), o);
  };
  const SimplifyResult gh97 = library(0);
  const std::string unfitted = made("forget.obj", "--no-refit");
  EXPECT_TRUE(unfitted == [&] {
    save_mesh(dir + "/forget_library.obj", library(0.85).mesh);
    return slurp(dir + "/forget_library.obj");
  }()) << "--no-refit differs from the library with the command line's forgetting";
  EXPECT_TRUE(plain == [&] {
    save_mesh(dir + "/library.obj", gh97.mesh);
    return slurp(dir + "/library.obj");
  }()) << "--no-refit differs from the library's default (GH97 as published)";
  ASSERT_EQ(run("simplify " + in + " " + dir + "/j.obj --faces 600 --json > " + dir + "/line.json"), 0);
  const std::string line = slurp(dir + "/line.json");
  EXPECT_NE(line.find("\"refit_rounds\":2,"), std::string::npos) << line;
  const auto number_after = [&](const std::string& key) {
    const std::size_t at = line.find("\"" + key + "\":");
    return at == std::string::npos ? NAN : std::stod(line.substr(at + key.size() + 3));
  };
  EXPECT_LT(number_after("refit_rms_after"), number_after("refit_rms_before")) << line;
  // Other placements keep their vertices where they put them: endpoints stay input vertices.
  EXPECT_TRUE(made("ends.obj", "--placement endpoints") ==
              made("ends_plain.obj", "--placement endpoints --no-refit"));
  EXPECT_NE(made("ends_fit.obj", "--placement endpoints --refit-sample 2"),
            made("ends2.obj", "--placement endpoints"));
  // A record replays the contractions only, so --record turns the default refit off.
  EXPECT_TRUE(made("rec.obj", "--record " + dir + "/run.qrec") == unfitted);
  // The LOD chain refits its levels the same way.
  ASSERT_EQ(run("lod " + in + " " + dir + "/lod --faces 600 --format obj"), 0);
  EXPECT_TRUE(fitted == slurp(dir + "/lod/in_lod0.obj")) << "lod level differs from simplify";
  // --no-refit with a refit option is a contradiction: refused, nothing written.
  EXPECT_NE(run("simplify " + in + " " + dir + "/both.obj --faces 600 --no-refit --refit 2>/dev/null"), 0);
  EXPECT_FALSE(std::filesystem::exists(dir + "/both.obj"));
}

}  // namespace
}  // namespace qem
