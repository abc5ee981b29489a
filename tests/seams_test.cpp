// Seams with appearance attributes (issue 18): they stay closed through the refit at several
// targets, a mirrored atlas's mirror line is a seam, seams and named vertices can be locked,
// protected vertices keep their seams, and the permissive mode crosses seams to reach targets that
// strict seams block. The command line's --lock, --lock-property and --seams, and its refusal of
// bad attribute data, are tested as a user runs them.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "qem/error.h"
#include "qem/io.h"
#include "qem/measure.h"
#include "qem/simplify.h"
#include "test_meshes.h"

using namespace qem;
using test::attribute;
using test::chart_grid;
using test::open_edges_welded;
using test::uv_cube;
using test::uv_sphere;
namespace fs = std::filesystem;

namespace {

using Point = std::array<double, 3>;

Point position(const Mesh& m, std::uint32_t v) { return {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]}; }

std::set<Point> positions_of(const Mesh& m) {
  std::set<Point> out;
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v) out.insert(position(m, v));
  return out;
}

// The input vertices on a seam: positions held by more than one referenced vertex.
std::vector<std::uint8_t> seam_vertices(const Mesh& m) {
  std::map<Point, int> count;
  std::vector<std::uint8_t> used(m.vertex_count(), 0);
  for (std::uint32_t v : m.indices) used[v] = 1;
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v)
    if (used[v]) ++count[position(m, v)];
  std::vector<std::uint8_t> seam(m.vertex_count(), 0);
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v) seam[v] = used[v] && count[position(m, v)] > 1;
  return seam;
}

// The positions on faces of more than one material.
std::set<Point> on_material_boundary(const Mesh& m) {
  std::map<Point, std::set<std::uint32_t>> at;
  for (std::size_t f = 0; f < m.face_count(); ++f)
    for (int k = 0; k < 3; ++k) at[position(m, m.indices[3 * f + k])].insert(m.face_materials[f]);
  std::set<Point> out;
  for (const auto& [p, materials] : at)
    if (materials.size() > 1) out.insert(p);
  return out;
}

}  // namespace

TEST(Seams, UvCubeAndSphereStayClosedThroughTheRefit) {
  const Mesh cube = uv_cube(16, 0.15, false), sphere = uv_sphere(40, 80);
  ASSERT_EQ(open_edges_welded(cube), 0u);
  ASSERT_EQ(open_edges_welded(sphere), 0u);
  for (const Mesh* in : {&cube, &sphere})
    for (double ratio : {0.5, 0.2, 0.05, 0.01}) {
      SimplifyOptions o;
      o.target_ratio = ratio;
      o.refit_rounds = 3;
      o.map_input_vertices = true;
      const SimplifyResult r = simplify(*in, o);
      SCOPED_TRACE((in == &cube ? "cube at " : "sphere at ") + std::to_string(ratio));
      EXPECT_EQ(open_edges_welded(r.mesh), 0u) << "a crack opened along a seam";
      EXPECT_GT(r.refit_rounds, 0u) << "the refit did not run";
      EXPECT_LT(r.refit_rms_after, r.refit_rms_before);
      // Seam vertices stay exactly where they were, with their UVs; every UV stays in [0, 1].
      const VertexAttribute& uv = attribute(r.mesh, AttributeKind::TexCoord);
      const std::vector<std::uint8_t> seam = seam_vertices(*in);
      std::size_t seam_checked = 0, moved_by_refit = 0;
      for (std::uint32_t v = 0; v < r.mesh.vertex_count(); ++v) {
        const std::uint32_t s = r.vertex_source[v];
        for (int c = 0; c < 2; ++c) {
          EXPECT_GE(uv.values[2 * v + c], -1e-9);
          EXPECT_LE(uv.values[2 * v + c], 1 + 1e-9);
        }
        const bool stayed = position(r.mesh, v) == position(*in, s);
        if (!seam[s]) {
          moved_by_refit += !stayed;
          continue;
        }
        ++seam_checked;
        EXPECT_TRUE(stayed) << "seam vertex " << v << " moved";
        EXPECT_EQ(uv.values[2 * v], in->attributes[0].values[2 * s]);
        EXPECT_EQ(uv.values[2 * v + 1], in->attributes[0].values[2 * s + 1]);
      }
      EXPECT_GT(seam_checked, 8u);
      EXPECT_GT(moved_by_refit, 0u);
    }
}

TEST(Seams, FlatShadedCubeKeepsItsSidesAndNormals) {
  // Each side flat with its own normal: the cube's edges are normal creases. Simplified as far as
  // it goes, it is the 12-triangle cube, each face's normals its side's, through the refit too.
  const Mesh in = uv_cube(8, 0, true);  // n a power of 2: the sides' shared coordinates agree exactly
  for (unsigned refit : {0u, 3u}) {
    SimplifyOptions o;
    o.target_faces = 12;
    o.refit_rounds = refit;
    const SimplifyResult r = simplify(in, o);
    SCOPED_TRACE("refit rounds " + std::to_string(refit));
    EXPECT_EQ(r.mesh.face_count(), 12u);
    EXPECT_EQ(r.mesh.vertex_count(), 24u);  // 4 wedges a side: one per corner and side
    EXPECT_EQ(open_edges_welded(r.mesh), 0u);
    const VertexAttribute& n = attribute(r.mesh, AttributeKind::Normal);
    for (std::size_t f = 0; f < r.mesh.face_count(); ++f) {
      const std::uint32_t* t = &r.mesh.indices[3 * f];
      Point p[3];
      for (int k = 0; k < 3; ++k) {
        p[k] = position(r.mesh, t[k]);
        for (int c = 0; c < 3; ++c) EXPECT_EQ(std::abs(p[k][c]), 1.0) << "a corner left the cube's corner";
      }
      const double e1[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
      const double e2[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
      const double g[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      const double len = std::hypot(g[0], g[1], g[2]);
      ASSERT_GT(len, 0);
      for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(n.values[3 * t[k] + c], g[c] / len, 1e-12) << "face " << f;
    }
  }
}

TEST(Seams, MirroredUvEdgeIsASeam) {
  // A wavy grid whose right half mirrors the left half's UVs (u = 2x, then 2 - 2x): the vertices
  // on x = 0.5 are shared, with one UV each, and the UV triangles of the two halves turn opposite
  // ways. The mirror line must stay: no face straddles it, its vertices keep x = 0.5 and u = 1,
  // and it is one vertex per position in the output as in the input.
  const int n = 40;
  Mesh in = test::height_field(n, [](double x, double y) { return 0.1 * std::sin(7 * x + 1) * std::cos(5 * y); });
  VertexAttribute uv{"TEXCOORD_0", AttributeKind::TexCoord, 2, {}};
  for (std::size_t v = 0; v < in.vertex_count(); ++v) {
    const double x = in.positions[3 * v], y = in.positions[3 * v + 1];
    uv.values.insert(uv.values.end(), {x <= 0.5 ? 2 * x : 2 - 2 * x, y});
  }
  // Smooth normals too: a line vertex that stays refits them over both sides' faces at once, so
  // its two sides' wedges stay equal (one vertex).
  VertexAttribute normal{"NORMAL", AttributeKind::Normal, 3, {}};
  for (std::size_t v = 0; v < in.vertex_count(); ++v) {
    const double x = in.positions[3 * v], y = in.positions[3 * v + 1];
    const double gx = 0.7 * std::cos(7 * x + 1) * std::cos(5 * y), gy = -0.5 * std::sin(7 * x + 1) * std::sin(5 * y);
    const double len = std::sqrt(gx * gx + gy * gy + 1);
    normal.values.insert(normal.values.end(), {-gx / len, -gy / len, 1 / len});
  }
  in.attributes = {uv, normal};
  for (Scheme scheme : {Scheme::Passes, Scheme::Greedy}) {
    SimplifyOptions o;
    o.scheme = scheme;
    o.target_ratio = 0.05;
    o.refit_rounds = 2;
    const SimplifyResult r = simplify(in, o);
    SCOPED_TRACE(to_string(scheme));
    EXPECT_LE(r.mesh.face_count(), in.face_count() / 20);
    const VertexAttribute& out_uv = r.mesh.attributes[0];
    std::set<Point> on_line;
    std::size_t line_vertices = 0;
    for (std::uint32_t v = 0; v < r.mesh.vertex_count(); ++v)
      if (r.mesh.positions[3 * v] == 0.5) {
        on_line.insert(position(r.mesh, v)), ++line_vertices;
        EXPECT_EQ(out_uv.values[2 * v], 1.0);
      }
    EXPECT_GE(on_line.size(), 2u);
    EXPECT_EQ(line_vertices, on_line.size()) << "the mirror line's vertices were split in the output";
    for (std::size_t f = 0; f < r.mesh.face_count(); ++f) {
      bool left = false, right = false;
      for (int k = 0; k < 3; ++k) {
        const double x = r.mesh.positions[3 * r.mesh.indices[3 * f + k]];
        left |= x < 0.5, right |= x > 0.5;
      }
      EXPECT_FALSE(left && right) << "face " << f << " crosses the mirror line";
    }
  }
}

TEST(Seams, LockSeamsKeepsEverySeamVertex) {
  const Mesh in = uv_sphere(30, 60);
  const std::vector<std::uint8_t> seam = seam_vertices(in);
  SimplifyOptions o;
  o.target_ratio = 0.1;
  o.lock_seams = true;
  o.refit_rounds = 2;
  o.map_input_vertices = true;
  const SimplifyResult r = simplify(in, o);
  EXPECT_LT(r.mesh.face_count(), in.face_count() / 4);
  // Every seam position is still there, exactly (a wedge of it may go with its faces: a pole's
  // wedges are one per face around it).
  const std::set<Point> kept = positions_of(r.mesh);
  std::size_t checked = 0;
  for (std::uint32_t v = 0; v < in.vertex_count(); ++v) {
    if (!seam[v]) continue;
    EXPECT_TRUE(kept.count(position(in, v))) << "seam vertex " << v << " moved or went";
    ++checked;
  }
  EXPECT_GT(checked, 60u);
}

TEST(Seams, PermissiveCrossesSeamsToReachTheTarget) {
  // A closed cube of 2 x 2-cell charts, two materials: strict seams stop far above the target
  // (every point where charts meet stays); permissive reaches it, with no crack and without
  // merging the two materials.
  const Mesh in = uv_cube(16, 0.1, false, 2);
  ASSERT_EQ(open_edges_welded(in), 0u);
  const std::set<Point> boundary = on_material_boundary(in);
  SimplifyOptions o;
  o.target_faces = 150;
  o.seams = SeamMode::Strict;
  const SimplifyResult strict = simplify(in, o);
  EXPECT_GT(strict.mesh.face_count(), 2 * o.target_faces) << "the mesh does not test what it should";
  o.seams = SeamMode::Permissive;
  o.refit_rounds = 2;
  for (Scheme scheme : {Scheme::Passes, Scheme::Greedy}) {
    o.scheme = scheme;
    const SimplifyResult r = simplify(in, o);
    SCOPED_TRACE(to_string(scheme));
    EXPECT_LE(r.mesh.face_count(), o.target_faces);
    EXPECT_EQ(r.stop_reason, StopReason::TargetReached);
    EXPECT_EQ(open_edges_welded(r.mesh), 0u) << "a crack opened";
    ASSERT_EQ(r.mesh.face_materials.size(), r.mesh.face_count());
    for (std::size_t f = 0; f < r.mesh.face_count(); ++f)
      EXPECT_EQ(r.mesh.face_materials[f], in.face_materials[r.face_source[f]]);
    for (const Point& p : on_material_boundary(r.mesh))
      EXPECT_TRUE(boundary.count(p)) << "a point of both materials left the material boundary";
  }
}

TEST(Seams, JunctionsMergeIntoJunctionsAndNothingElseCrosses) {
  // The default seams (SeamMode::Junctions): a vertex where three or more charts meet may
  // collapse onto another such vertex, so a cube of 2 x 2-cell charts, two materials, goes further
  // than with junctions fixed, with no crack and the materials apart, and every output vertex
  // stays on the input's seams where it was one.
  const Mesh in = uv_cube(16, 0.1, false, 2);
  const std::set<Point> boundary = on_material_boundary(in);
  SimplifyOptions o;
  o.target_faces = 150;
  o.seams = SeamMode::Strict;
  const SimplifyResult fixed = simplify(in, o);
  o.seams = SeamMode::Junctions;
  std::set<Point> seams;
  const std::vector<std::uint8_t> on_seam = seam_vertices(in);
  for (std::uint32_t v = 0; v < in.vertex_count(); ++v)
    if (on_seam[v]) seams.insert(position(in, v));
  for (Scheme scheme : {Scheme::Passes, Scheme::Greedy}) {
    o.scheme = scheme;
    const SimplifyResult r = simplify(in, o);
    SCOPED_TRACE(to_string(scheme));
    EXPECT_LT(r.mesh.face_count(), fixed.mesh.face_count() * 3 / 4) << "no junction merged";
    EXPECT_EQ(open_edges_welded(r.mesh), 0u) << "a crack opened";
    for (std::size_t f = 0; f < r.mesh.face_count(); ++f)
      EXPECT_EQ(r.mesh.face_materials[f], in.face_materials[r.face_source[f]]);
    for (const Point& p : on_material_boundary(r.mesh))
      EXPECT_TRUE(boundary.count(p)) << "a point of both materials left the material boundary";
    const std::vector<std::uint8_t> out_seam = seam_vertices(r.mesh);
    for (std::uint32_t v = 0; v < r.mesh.vertex_count(); ++v)
      if (out_seam[v]) {
        EXPECT_TRUE(seams.count(position(r.mesh, v))) << "a seam left its line";
      }
  }
  // One junction only (four charts meeting at the middle of a grid): nothing to merge it into, so
  // the run is exactly that with junctions fixed; a seam of two charts is never crossed.
  const Mesh quarters = chart_grid(16, 8);
  o.scheme = Scheme::Passes;
  o.target_faces = 1;
  const SimplifyResult merged = simplify(quarters, o);
  o.seams = SeamMode::Strict;
  const SimplifyResult kept = simplify(quarters, o);
  EXPECT_GT(kept.mesh.face_count(), o.target_faces) << "the mesh does not test what it should";
  EXPECT_EQ(merged.mesh.indices, kept.mesh.indices);
  EXPECT_EQ(merged.mesh.positions, kept.mesh.positions);
  EXPECT_EQ(merged.mesh.attributes[0].values, kept.mesh.attributes[0].values);
}

TEST(Seams, ProtectedVerticesKeepTheirSeamsInPermissiveMode) {
  // Every vertex protected: permissive makes exactly what strict makes.
  const Mesh in = chart_grid(24, 3);
  const std::vector<std::uint8_t> all(in.vertex_count(), 1);
  SimplifyOptions o;
  o.target_faces = 40;
  o.seams = SeamMode::Strict;
  const SimplifyResult strict = simplify(in, o);
  EXPECT_GT(strict.mesh.face_count(), o.target_faces) << "the mesh does not test what it should";
  o.seams = SeamMode::Permissive;
  o.vertex_protect = all;
  const SimplifyResult protect = simplify(in, o);
  EXPECT_EQ(protect.mesh.indices, strict.mesh.indices);
  EXPECT_EQ(protect.mesh.positions, strict.mesh.positions);
  EXPECT_EQ(protect.mesh.attributes[0].values, strict.mesh.attributes[0].values);
  o.vertex_protect = {};
  const SimplifyResult permissive = simplify(in, o);
  EXPECT_LT(permissive.mesh.face_count(), strict.mesh.face_count()) << "permissive crossed nothing";
  // A wrong size is refused.
  const std::vector<std::uint8_t> short_list(3, 1);
  o.vertex_protect = short_list;
  EXPECT_THROW(simplify(in, o), Error);
}

TEST(Seams, CreasesModeCrossesCreasesButNoUvSeam) {
  // SeamMode::Creases (`--seams creases`). A grid of UV charts has UV seams only: the mode
  // makes exactly what strict makes. A flat-shaded cube without its UVs has normal creases only:
  // exactly what permissive makes, which crosses them to go further than strict.
  SimplifyOptions o;
  o.target_faces = 40;
  o.seams = SeamMode::Strict;
  const Mesh charts = chart_grid(24, 3);
  const SimplifyResult strict = simplify(charts, o);
  EXPECT_GT(strict.mesh.face_count(), o.target_faces) << "the mesh does not test what it should";
  o.seams = SeamMode::Creases;
  const SimplifyResult kept = simplify(charts, o);
  EXPECT_EQ(kept.mesh.indices, strict.mesh.indices);
  EXPECT_EQ(kept.mesh.positions, strict.mesh.positions);
  EXPECT_EQ(kept.mesh.attributes[0].values, strict.mesh.attributes[0].values);

  Mesh cube = uv_cube(8, 0.1, true);
  std::erase_if(cube.attributes, [](const VertexAttribute& a) { return a.kind == AttributeKind::TexCoord; });
  ASSERT_EQ(cube.attributes.size(), 1u);
  o.target_faces = 4;
  o.seams = SeamMode::Strict;
  const SimplifyResult cube_strict = simplify(cube, o);
  o.seams = SeamMode::Permissive;
  const SimplifyResult cube_permissive = simplify(cube, o);
  o.seams = SeamMode::Creases;
  const SimplifyResult creases = simplify(cube, o);
  EXPECT_LT(cube_permissive.mesh.face_count(), cube_strict.mesh.face_count()) << "permissive crossed nothing";
  EXPECT_EQ(creases.mesh.indices, cube_permissive.mesh.indices);
  EXPECT_EQ(creases.mesh.positions, cube_permissive.mesh.positions);
  EXPECT_EQ(open_edges_welded(creases.mesh), 0u) << "a crack opened";
}

TEST(Seams, AChartWhoseFacesAllDiedIsNoSeam) {
  // One-cell UV islands in a grid: once an island's two faces are gone, its corners hold one wedge
  // each and must be ordinary vertices again (removable, placed freely). A dead wedge left in its
  // vertex's ring kept them seams, which refused every collapse that removes them: the run stopped
  // at 10 faces here, where the grid without islands goes on to its last face.
  const Mesh islands = chart_grid(6, [](int i, int j) {
    return i % 3 == 1 && j % 3 == 1 ? std::pair{i + 1, j + 1} : std::pair{0, 0};
  });
  const Mesh plain = chart_grid(6, 6);
  ASSERT_EQ(islands.vertex_count(), plain.vertex_count() + 4 * 4) << "four islands of four wedges";
  SimplifyOptions o;
  o.as_far_as_possible = true;
  // On both border kinds. Under exact borders (the default) an island's corner and a rim vertex
  // next to it could not collapse while the island lived (the rim vertex must survive, the
  // corner's island wedge has nowhere to go), and such a refusal locked the pair for good: the run
  // stopped at 12 faces against the plain grid's 1. A refused pair is blocked now, and retried
  // once the island is gone.
  for (bool exact : {true, false}) {
    for (Scheme scheme : {Scheme::Passes, Scheme::Greedy}) {
      SCOPED_TRACE(std::string(exact ? "exact borders, " : "penalty borders, ") + to_string(scheme));
      o.exact_border = exact;
      o.scheme = scheme;
      const SimplifyResult r = simplify(islands, o), reference = simplify(plain, o);
      EXPECT_EQ(r.mesh.face_count(), reference.mesh.face_count());
      EXPECT_EQ(open_edges_welded(r.mesh), open_edges_welded(reference.mesh));
    }
  }
}

TEST(Seams, ADoubleSidedSheetKeepsItsRimAndOpensNoCrack) {
  // trimesh_chair.obj's case: every face also given reversed, with other UVs (a two-sided sheet).
  // Welded by position with both sides, the sheet is closed (its rim edges have a face on each
  // side), so qem measure and attr_metric.py count no open edge in it. qem drops each reversed
  // copy as a duplicate, so the sheet's rim is a border of what it simplifies: under exact borders
  // (the default) that border stays on the input's rim, and the reversed copies of the output faces
  // along it are put back (SimplifyOptions::two_sided), so no edge is open. With one side
  // only, the rim is open, and no edge may open anywhere else.
  Mesh in = chart_grid(12, 4);
  const std::uint32_t front_vertices = std::uint32_t(in.vertex_count()), front_faces = std::uint32_t(in.face_count());
  VertexAttribute& uv = in.attributes[0];
  for (std::uint32_t v = 0; v < front_vertices; ++v) {  // the back side's vertices: same places, other UVs
    for (int c = 0; c < 3; ++c) in.positions.push_back(in.positions[3 * v + c]);
    uv.values.insert(uv.values.end(), {1 - uv.values[2 * v], uv.values[2 * v + 1]});
  }
  for (std::uint32_t f = 0; f < front_faces; ++f)
    for (int k : {0, 2, 1}) in.indices.push_back(front_vertices + in.indices[3 * f + k]);
  ASSERT_EQ(open_edges_welded(in), 0u) << "both sides together: closed";
  SimplifyOptions o;
  for (double ratio : {0.5, 0.1, 0.01}) {
    SCOPED_TRACE("ratio " + std::to_string(ratio));
    o.target_ratio = ratio;
    o.two_sided = TwoSided::Rims;
    const SimplifyResult two = simplify(in, o);
    EXPECT_EQ(two.input_faces, front_faces) << "the reversed copies are dropped as duplicates";
    EXPECT_GT(two.twin_faces, 0u);
    EXPECT_EQ(open_edges_welded(two.mesh), 0u) << "the rim's reversed copies are back: nothing open";
    o.two_sided = TwoSided::None;
    const SimplifyResult r = simplify(in, o);
    EXPECT_EQ(r.twin_faces, 0u);
    EXPECT_GT(open_edges_welded(r.mesh), 0u) << "the rim is open once one side is dropped";
    // Each open edge joins two points of the rim (the unit square's outline; an edge may cut a
    // corner the run removed at its size): an open edge with an end inside would be a crack.
    std::map<std::pair<Point, Point>, int> uses;
    for (std::size_t f = 0; f < r.mesh.face_count(); ++f)
      for (int k = 0; k < 3; ++k) {
        const Point a = position(r.mesh, r.mesh.indices[3 * f + k]), b = position(r.mesh, r.mesh.indices[3 * f + (k + 1) % 3]);
        ++uses[{std::min(a, b), std::max(a, b)}];
      }
    const auto on_rim = [](const Point& p) { return p[0] == 0 || p[0] == 1 || p[1] == 0 || p[1] == 1; };
    for (const auto& [edge, n] : uses)
      EXPECT_TRUE(n > 1 || (on_rim(edge.first) && on_rim(edge.second))) << "an open edge off the sheet's rim: a crack";
  }
}

namespace {

struct CliRun {
  int exit_code;
  std::string out;
};

CliRun run_cli(const std::string& args) {
  const std::string cmd = std::string(QEM_CLI_PATH) + " " + args + " 2>&1";
  CliRun r{-1, {}};
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, pipe)) r.out.append(buf, n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace

TEST(Seams, CommandLineLocksSeamsAndNamedVertices) {
  const std::string dir = test::temp_dir();
  const Mesh sphere = uv_sphere(20, 40);
  const std::string obj = dir + "/seams_sphere.obj", out = dir + "/seams_sphere_out.obj";
  save_mesh(obj, sphere);
  CliRun r = run_cli("simplify " + obj + " " + out + " --ratio 0.1 --lock seams --quiet --force");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  {
    const std::set<Point> kept = positions_of(load_mesh(out));
    const std::vector<std::uint8_t> seam = seam_vertices(sphere);
    for (std::uint32_t v = 0; v < sphere.vertex_count(); ++v)
      if (seam[v]) {
        EXPECT_TRUE(kept.count(position(sphere, v))) << "seam vertex " << v << " is gone";
      }
  }

  // A PLY vertex property names the vertices to lock.
  Mesh ball = test::icosphere(3);
  VertexProperty keep{"keep", std::vector<double>(ball.vertex_count(), 0)};
  for (std::size_t v = 0; v < ball.vertex_count(); v += 9) keep.values[v] = 1;
  ball.vertex_properties = {keep};
  const std::string ply = dir + "/seams_keep.ply", ply_out = dir + "/seams_keep_out.ply";
  save_mesh(ply, ball);
  ball = load_mesh(ply);  // as the file holds it (float coordinates)
  r = run_cli("simplify " + ply + " " + ply_out + " --ratio 0.05 --lock-property keep --quiet --force");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const Mesh simplified = load_mesh(ply_out);
  EXPECT_LT(simplified.face_count(), ball.face_count() / 4);
  const std::set<Point> kept = positions_of(simplified);
  for (std::uint32_t v = 0; v < ball.vertex_count(); v += 9)
    EXPECT_TRUE(kept.count(position(ball, v))) << "locked vertex " << v << " moved or went";

  // An unknown property: a clear error, and no output.
  const std::string none = dir + "/seams_none.ply";
  fs::remove(none);
  r = run_cli("simplify " + ply + " " + none + " --ratio 0.05 --lock-property nothere --quiet");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.out.find("nothere"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("keep"), std::string::npos) << "the error should list the properties there are: " << r.out;
  EXPECT_FALSE(fs::exists(none));
}

TEST(Seams, CommandLineRefitsAttributesOnlyWhenAsked) {
  // The default's light refit is left out with texture coordinates or normals (it raised the UV
  // error); --refit makes it, and the seams stay closed.
  const std::string dir = test::temp_dir();
  const std::string obj = dir + "/seams_refit.obj", out = dir + "/seams_refit_out.obj";
  save_mesh(obj, uv_sphere(30, 60));
  ASSERT_EQ(open_edges_welded(load_mesh(obj)), 0u);
  CliRun plain = run_cli("simplify " + obj + " " + out + " --ratio 0.1 --json --quiet --force");
  ASSERT_EQ(plain.exit_code, 0) << plain.out;
  EXPECT_NE(plain.out.find("\"refit_rounds\":0,"), std::string::npos) << plain.out;
  CliRun asked = run_cli("simplify " + obj + " " + out + " --ratio 0.1 --refit --json --quiet --force");
  ASSERT_EQ(asked.exit_code, 0) << asked.out;
  EXPECT_EQ(asked.out.find("\"refit_rounds\":0,"), std::string::npos) << asked.out;
  EXPECT_NE(asked.out.find("\"refit_rounds\":"), std::string::npos) << asked.out;
  EXPECT_EQ(open_edges_welded(load_mesh(out)), 0u);
  // Colours only: the default's light refit is made (it held the colour error within 3 % on the
  // shared colour assets and lowered E by up to half), and holds the seams too.
  Mesh coloured = uv_sphere(30, 60);
  VertexAttribute color{"COLOR_0", AttributeKind::Color, 3, {}};
  for (std::size_t v = 0; v < coloured.vertex_count(); ++v)
    for (int c = 0; c < 3; ++c) color.values.push_back(0.5 + 0.5 * coloured.positions[3 * v + c]);
  coloured.attributes = {color};
  const std::string ply = dir + "/seams_refit_colour.ply", ply_out = dir + "/seams_refit_colour_out.ply";
  save_mesh(ply, coloured);
  CliRun colour = run_cli("simplify " + ply + " " + ply_out + " --ratio 0.1 --json --quiet --force");
  ASSERT_EQ(colour.exit_code, 0) << colour.out;
  EXPECT_NE(colour.out.find("\"refit_rounds\":"), std::string::npos) << colour.out;
  EXPECT_EQ(colour.out.find("\"refit_rounds\":0,"), std::string::npos) << colour.out;  // a round was kept
  EXPECT_EQ(open_edges_welded(load_mesh(ply_out)), 0u);
}

TEST(Seams, CommandLinePermissiveReachesTheTarget) {
  const std::string dir = test::temp_dir();
  const std::string obj = dir + "/seams_charts.obj", out = dir + "/seams_charts_out.obj";
  save_mesh(obj, chart_grid(40, 2));
  CliRun strict =
      run_cli("simplify " + obj + " " + out + " --faces 160 --seams strict --json --quiet --force");
  ASSERT_EQ(strict.exit_code, 0) << strict.out;
  EXPECT_EQ(strict.out.find("\"out_faces\":160"), std::string::npos) << strict.out;
  CliRun permissive = run_cli("simplify " + obj + " " + out + " --faces 160 --seams permissive --json --quiet --force");
  ASSERT_EQ(permissive.exit_code, 0) << permissive.out;
  // Reached: an interior contraction removes two faces, so the run may stop one below the target.
  EXPECT_LE(load_mesh(out).face_count(), 160u);
  EXPECT_GE(load_mesh(out).face_count(), 159u);
  CliRun bad = run_cli("simplify " + obj + " " + out + " --faces 160 --seams sometimes --quiet --force");
  EXPECT_NE(bad.exit_code, 0);
}

TEST(Seams, BadAttributeDataGivesAClearErrorAndNoOutput) {
  SimplifyOptions o;
  o.target_faces = 10;
  Mesh in = uv_sphere(6, 12);
  in.attributes[0].values[5] = std::nan("");
  try {
    simplify(in, o);
    ADD_FAILURE() << "a NaN UV was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("TEXCOORD_0"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("vertex 2"), std::string::npos) << e.what();
  }
  in = uv_sphere(6, 12);
  in.attributes[1].values.pop_back();
  try {
    simplify(in, o);
    ADD_FAILURE() << "a short NORMAL attribute was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("NORMAL"), std::string::npos) << e.what();
  }
  // From a file: the reader names the file and line, exits non-zero, and writes nothing.
  const std::string dir = test::temp_dir();
  const std::string obj = dir + "/seams_nan_uv.obj", out = dir + "/seams_nan_uv_out.obj";
  {
    std::ofstream f(obj);
    f << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt nan 0\nvt 0 1\nf 1/1 2/2 3/3\nf 2/2 4/1 3/3\n";
  }
  fs::remove(out);
  const CliRun r = run_cli("simplify " + obj + " " + out + " --faces 1 --quiet");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.out.find("seams_nan_uv.obj"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("6"), std::string::npos) << "the error should name line 6: " << r.out;
  EXPECT_FALSE(fs::exists(out));
}

namespace {

// A wavy grid (n even) with polar texture coordinates about its centre, u the angle / 2 pi and v
// the distance: the faces just below the ray from the centre to the right border have u = 1 there
// (their own vertices on the ray), those above u = 0. A seam that runs from the border to the
// centre and ends there: the centre holds one wedge.
Mesh polar_slit_grid(int n) {
  Mesh m = test::height_field(n, [](double x, double y) { return 0.05 * std::sin(6 * x) * std::cos(5 * y); });
  const std::size_t grid_vertices = m.vertex_count();
  VertexAttribute uv{"TEXCOORD_0", AttributeKind::TexCoord, 2, {}};
  const auto on_ray = [&](std::uint32_t v) { return m.positions[3 * v + 1] == 0.5 && m.positions[3 * v] > 0.5; };
  for (std::uint32_t v = 0; v < grid_vertices; ++v) {
    const double dx = m.positions[3 * v] - 0.5, dy = m.positions[3 * v + 1] - 0.5;
    double u = dx == 0 && dy == 0 ? 0.5 : std::atan2(dy, dx) / (2 * M_PI);
    if (u < 0) u += 1;
    uv.values.insert(uv.values.end(), {u, std::hypot(dx, dy)});
  }
  std::map<std::uint32_t, std::uint32_t> below;  // a ray vertex's copy with u = 1
  for (std::size_t f = 0; f < m.face_count(); ++f) {
    double cy = 0;
    for (int k = 0; k < 3; ++k) cy += m.positions[3 * m.indices[3 * f + k] + 1] / 3;
    if (cy > 0.5) continue;
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& v = m.indices[3 * f + k];
      if (!on_ray(v)) continue;
      auto [it, fresh] = below.try_emplace(v, std::uint32_t(m.vertex_count()));
      if (fresh) {
        m.positions.insert(m.positions.end(), {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]});
        uv.values.insert(uv.values.end(), {1.0, uv.values[2 * v + 1]});
      }
      v = it->second;
    }
  }
  m.attributes = {uv};
  return m;
}

}  // namespace

TEST(Seams, ASeamEndingInsideAChartShortensAlongItself) {
  // The slit's last edge, from the vertex before the centre to the centre, collapses into the
  // centre with both of that vertex's wedges going to the centre's one (meshoptimizer's half
  // seam): the seam shortens along itself and still ends at the centre. Refusing it (two wedges
  // into one) kept that vertex, and the faces around it, to the end (66 faces, not 64).
  const int n = 16;
  const Mesh in = polar_slit_grid(n);
  ASSERT_EQ(in.vertex_count(), std::size_t((n + 1) * (n + 1) + n / 2));
  SimplifyOptions o;
  o.as_far_as_possible = true;
  o.lock_border = true;
  for (Scheme scheme : {Scheme::Passes, Scheme::Greedy}) {
    SCOPED_TRACE(to_string(scheme));
    o.scheme = scheme;
    const SimplifyResult r = simplify(in, o);
    EXPECT_EQ(open_edges_welded(r.mesh, true), 0u) << "a crack opened along the slit";
    // The border is locked: what is left inside is one vertex, where the slit ends (an ordinary
    // vertex, which may move), with a fan of one face per border edge around it.
    std::size_t inside = 0;
    for (const Point& p : positions_of(r.mesh)) inside += p[0] > 0 && p[0] < 1 && p[1] > 0 && p[1] < 1;
    EXPECT_EQ(inside, 1u);
    EXPECT_EQ(r.mesh.face_count(), std::size_t(4 * n));
    const VertexAttribute& uv = r.mesh.attributes[0];
    std::set<Point> on_ray;
    for (std::uint32_t v = 0; v < r.mesh.vertex_count(); ++v) {
      const Point p = position(r.mesh, v);
      if (p[1] == 0.5 && p[0] > 0.5) {
        on_ray.insert(p);
        EXPECT_TRUE(uv.values[2 * v] == 0 || uv.values[2 * v] == 1) << "a vertex on the slit left its side";
      }
    }
    // No face straddles the slit: its corners' u stay on one side of it.
    for (std::size_t f = 0; f < r.mesh.face_count(); ++f) {
      double lo = 1, hi = 0;
      for (int k = 0; k < 3; ++k) {
        const double u = uv.values[2 * r.mesh.indices[3 * f + k]];
        lo = std::min(lo, u), hi = std::max(hi, u);
      }
      EXPECT_LT(hi - lo, 0.75) << "face " << f << " crosses the slit";
    }
    // The slit is one edge, from there to its border end.
    EXPECT_EQ(on_ray.size(), 1u);
    EXPECT_TRUE(on_ray.count(Point{1.0, 0.5, 0.05 * std::sin(6.0) * std::cos(2.5)}));
  }
}

namespace {

// A wavy grid (n a multiple of 4) with smooth normals, and at every interior vertex (i, j) with i
// and j = 2 mod 4 one face whose corner there has its own, tilted normal: a crease that ends one
// face away (Duck.glb has such corners along its beak). `odd` false: the plain grid.
Mesh odd_corner_grid(int n, bool odd) {
  Mesh m = test::height_field(n, [](double x, double y) { return 0.05 * std::sin(6 * x) * std::cos(5 * y); });
  VertexAttribute normal{"NORMAL", AttributeKind::Normal, 3, {}};
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v) {
    const double x = m.positions[3 * v], y = m.positions[3 * v + 1];
    const double gx = 0.3 * std::cos(6 * x) * std::cos(5 * y), gy = -0.25 * std::sin(6 * x) * std::sin(5 * y);
    const double len = std::sqrt(gx * gx + gy * gy + 1);
    normal.values.insert(normal.values.end(), {-gx / len, -gy / len, 1 / len});
  }
  if (odd)
    for (int j = 2; j < n; j += 4)
      for (int i = 2; i < n; i += 4) {
        const std::size_t f = 2 * (std::size_t(j) * n + i);  // the cell's first face, (i, j) its first corner
        const std::uint32_t v = m.indices[3 * f], copy = std::uint32_t(m.vertex_count());
        m.positions.insert(m.positions.end(), {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]});
        normal.values.insert(normal.values.end(), {0.6, 0, 0.8});
        m.indices[3 * f] = copy;
      }
  m.attributes = {normal};
  return m;
}

}  // namespace

TEST(Seams, ACreaseEndingOneFaceAwayDoesNotStopTheRun) {
  // Collapsing a neighbour of the odd corner into it: the neighbour's wedge meets the corner's
  // two wedges on the edge's two faces, but the odd one is on those faces only and dies with
  // them, so the neighbour's faces go on with the other (no seam moves: the crease is gone).
  // Refused as "one wedge into two", the odd corners held their vertices to the end.
  const int n = 16;
  const Mesh odd = odd_corner_grid(n, true), plain = odd_corner_grid(n, false);
  ASSERT_EQ(odd.vertex_count(), plain.vertex_count() + 16);
  SimplifyOptions o;
  o.as_far_as_possible = true;
  o.lock_border = true;
  for (Scheme scheme : {Scheme::Passes, Scheme::Greedy}) {
    SCOPED_TRACE(to_string(scheme));
    o.scheme = scheme;
    const SimplifyResult r = simplify(odd, o), reference = simplify(plain, o);
    EXPECT_EQ(r.mesh.face_count(), reference.mesh.face_count());
    EXPECT_EQ(open_edges_welded(r.mesh, true), 0u);
  }
}

TEST(Seams, ASurvivorThatStaysFitsItsNormalsToItsFaces) {
  // At every interior vertex (i, j), i and j = 2 mod 4, of a wavy grid the faces left of the
  // vertex carry a tilted normal at that corner: a crease that ends on both sides, so the vertex
  // holds two wedges and stays where it is when its neighbours collapse into it. The tilted wedge
  // then covers faces whose own normals are the surface's: its value is refitted to them
  // (Hoppe's optimum at the kept position) instead of being kept, which held the tilt over the
  // whole grown fan.
  const int n = 16;
  Mesh in = odd_corner_grid(n, false);
  VertexAttribute& normal = in.attributes[0];
  for (int j = 2; j < n; j += 4)
    for (int i = 2; i < n; i += 4) {
      const std::uint32_t v = std::uint32_t(j * (n + 1) + i), copy = std::uint32_t(in.vertex_count());
      in.positions.insert(in.positions.end(), {in.positions[3 * v], in.positions[3 * v + 1], in.positions[3 * v + 2]});
      normal.values.insert(normal.values.end(), {0.6, 0, 0.8});
      for (std::size_t f = 0; f < in.face_count(); ++f) {
        double cx = 0;
        for (int k = 0; k < 3; ++k) cx += in.positions[3 * in.indices[3 * f + k]] / 3;
        for (int k = 0; k < 3; ++k)
          if (in.indices[3 * f + k] == v && cx < in.positions[3 * v]) in.indices[3 * f + k] = copy;
      }
    }
  SimplifyOptions o;
  o.target_ratio = 0.25;
  MeasureOptions mo;
  mo.samples = 100000;
  for (Scheme scheme : {Scheme::Passes, Scheme::Greedy}) {
    SCOPED_TRACE(to_string(scheme));
    o.scheme = scheme;
    const SimplifyResult r = simplify(in, o);
    const MeasureResult m = measure(in, r.mesh, mo);
    ASSERT_TRUE(m.normal_rms_deg.has_value());
    // 3.40 degrees refitted; keeping the values gave 4.28 on the same 127 faces (5.9 against 7.4
    // at 10 %).
    EXPECT_LT(*m.normal_rms_deg, 3.8);
    EXPECT_EQ(open_edges_welded(r.mesh, true), 0u);
  }
}
