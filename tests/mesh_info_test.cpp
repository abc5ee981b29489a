// mesh_info on small meshes built in code, each with counts worked out by hand.
#include "qem/mesh_info.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <tuple>

#include "qem/error.h"
#include "qem/io.h"
#include "test_meshes.h"

namespace qem {
namespace {

/// Merges vertices with equal coordinates (first occurrence wins), so meshes built from separate
/// pieces can share vertices.
Mesh welded(const Mesh& in) {
  Mesh out;
  std::map<std::tuple<double, double, double>, std::uint32_t> index;
  std::vector<std::uint32_t> remap(in.vertex_count());
  for (std::size_t v = 0; v < in.vertex_count(); ++v) {
    auto key = std::make_tuple(in.positions[3 * v], in.positions[3 * v + 1], in.positions[3 * v + 2]);
    auto [it, inserted] = index.emplace(key, std::uint32_t(out.vertex_count()));
    if (inserted)
      out.positions.insert(out.positions.end(), in.positions.begin() + 3 * v,
                           in.positions.begin() + 3 * v + 3);
    remap[v] = it->second;
  }
  for (std::uint32_t i : in.indices) out.indices.push_back(remap[i]);
  return out;
}

void flip_face(Mesh& m, std::size_t f) { std::swap(m.indices[3 * f + 1], m.indices[3 * f + 2]); }

TEST(MeshInfo, CubeIsClosedGenusZero) {
  MeshInfo i = mesh_info(test::cube());
  EXPECT_EQ(i.vertices, 8u);
  EXPECT_EQ(i.faces, 12u);
  EXPECT_EQ(i.edges, 18u);
  EXPECT_EQ(i.boundary_edges, 0u);
  EXPECT_EQ(i.boundary_loops, 0u);
  EXPECT_EQ(i.non_manifold_edges, 0u);
  EXPECT_EQ(i.non_manifold_vertices, 0u);
  EXPECT_EQ(i.components, 1u);
  EXPECT_EQ(i.orientation_conflicts, 0u);
  EXPECT_EQ(i.duplicate_faces, 0u);
  EXPECT_EQ(i.degenerate_faces, 0u);
  EXPECT_EQ(i.unreferenced_vertices, 0u);
  EXPECT_EQ(i.euler, 2);
  EXPECT_EQ(i.genus, 0);
  EXPECT_TRUE(i.watertight());
  EXPECT_TRUE(i.manifold());
  EXPECT_DOUBLE_EQ(i.box.diagonal(), std::sqrt(3.0));
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(i.box.lo[k], 0.0);
    EXPECT_EQ(i.box.hi[k], 1.0);
  }
}

TEST(MeshInfo, IcosphereAndTetrahedronAreGenusZero) {
  MeshInfo s = mesh_info(test::icosphere(2));
  EXPECT_EQ(s.faces, 320u);
  EXPECT_EQ(s.edges, 480u);
  EXPECT_EQ(s.genus, 0);
  MeshInfo t = mesh_info(test::tetrahedron());
  EXPECT_EQ(t.edges, 6u);
  EXPECT_EQ(t.genus, 0);
  EXPECT_EQ(t.orientation_conflicts, 0u);
}

TEST(MeshInfo, GridHasOneBoundaryLoop) {
  const int n = 4;
  MeshInfo i = mesh_info(test::grid(n));
  EXPECT_EQ(i.vertices, 25u);
  EXPECT_EQ(i.faces, 32u);
  EXPECT_EQ(i.edges, 2u * n * (n + 1) + n * n);  // rows, columns, one diagonal per quad
  EXPECT_EQ(i.boundary_edges, 4u * n);
  EXPECT_EQ(i.boundary_loops, 1u);
  EXPECT_EQ(i.components, 1u);
  EXPECT_EQ(i.euler, 1);  // a disk
  EXPECT_EQ(i.genus, -1);
  EXPECT_FALSE(i.watertight());
  EXPECT_TRUE(i.manifold());
}

TEST(MeshInfo, TorusHasGenusOne) {
  // n x n grid wrapped in both directions (vertex indices modulo n): a closed torus.
  constexpr int n = 6;
  Mesh m;
  const double pi = std::acos(-1.0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double u = 2 * pi * i / n, v = 2 * pi * j / n;
      m.positions.insert(m.positions.end(),
                         {(2 + std::cos(v)) * std::cos(u), (2 + std::cos(v)) * std::sin(u), std::sin(v)});
    }
  auto id = [](int i, int j) { return std::uint32_t((j % n) * n + (i % n)); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  MeshInfo i = mesh_info(m);
  EXPECT_EQ(i.boundary_edges, 0u);
  EXPECT_EQ(i.orientation_conflicts, 0u);
  EXPECT_EQ(i.euler, 0);
  EXPECT_EQ(i.genus, 1);
}

TEST(MeshInfo, TwoCubesSharingAnEdgeAreNonManifold) {
  // The second cube's edge (0,0,0)-(0,0,1) lands on the first cube's edge (1,1,0)-(1,1,1).
  Mesh m = welded(test::concatenated(test::cube(), test::transformed(test::cube(), 1, 1, 1, 0)));
  MeshInfo i = mesh_info(m);
  EXPECT_EQ(i.vertices, 14u);
  EXPECT_EQ(i.edges, 35u);
  EXPECT_EQ(i.non_manifold_edges, 1u);
  EXPECT_EQ(i.non_manifold_vertices, 2u);  // the shared edge's ends: one fan per cube
  EXPECT_EQ(i.boundary_edges, 0u);
  EXPECT_EQ(i.components, 1u);
  EXPECT_FALSE(i.manifold());
  EXPECT_FALSE(i.watertight());
  EXPECT_EQ(i.genus, -1);
}

TEST(MeshInfo, TwoTetrahedraSharingAVertexHaveOneNonManifoldVertex) {
  Mesh a = test::tetrahedron();
  // Mirror through the vertex (1,1,1): the copy touches the original only there.
  Mesh b = test::transformed(a, -1, 2, 2, 2);
  for (std::size_t f = 0; f < b.face_count(); ++f) flip_face(b, f);  // mirroring flips orientation
  MeshInfo i = mesh_info(welded(test::concatenated(a, b)));
  EXPECT_EQ(i.vertices, 7u);
  EXPECT_EQ(i.non_manifold_edges, 0u);
  EXPECT_EQ(i.non_manifold_vertices, 1u);
  EXPECT_EQ(i.components, 1u);
  EXPECT_EQ(i.orientation_conflicts, 0u);
  EXPECT_EQ(i.genus, -1);  // not a manifold, so no genus
}

TEST(MeshInfo, FlippedFaceGivesOrientationConflicts) {
  Mesh m = test::cube();
  flip_face(m, 5);
  MeshInfo i = mesh_info(m);
  EXPECT_EQ(i.orientation_conflicts, 3u);
  EXPECT_TRUE(i.watertight());
  EXPECT_TRUE(i.manifold());
  EXPECT_EQ(i.genus, -1);
}

TEST(MeshInfo, DuplicateFacesCountedOncePerExtraCopy) {
  Mesh m = test::cube();
  // Face 0 again, once as stored and once reversed: same vertex set both times.
  m.indices.insert(m.indices.end(), {0, 2, 1, 1, 2, 0});
  MeshInfo i = mesh_info(m);
  EXPECT_EQ(i.duplicate_faces, 2u);
  EXPECT_EQ(i.non_manifold_edges, 3u);  // each edge of face 0 now has 4 faces
  EXPECT_EQ(i.edges, 18u);
  EXPECT_EQ(i.degenerate_faces, 0u);
}

TEST(MeshInfo, DegenerateFacesRepeatedIndexAndZeroArea) {
  Mesh m = test::grid(4);
  m.indices.insert(m.indices.end(), {0, 0, 6});  // repeated index: no edges
  m.indices.insert(m.indices.end(), {0, 1, 2});  // three collinear vertices of the first row
  MeshInfo i = mesh_info(m);
  EXPECT_EQ(i.degenerate_faces, 2u);
  EXPECT_EQ(i.zero_area_faces, 1u);
  // The zero-area face adds the edge 0-2 and makes 0-1 and 1-2 two-face edges.
  EXPECT_EQ(i.edges, 56u + 1u);
  EXPECT_EQ(i.boundary_edges, 16u - 2u + 1u);
  EXPECT_EQ(i.euler, 25 - 57 + 33);
}

TEST(MeshInfo, SeparateComponentsAndUnreferencedVertices) {
  Mesh m = test::concatenated(test::cube(), test::transformed(test::cube(), 1, 5, 0, 0));
  m = test::concatenated(m, test::transformed(test::tetrahedron(), 1, 0, 5, 0));
  m.positions.insert(m.positions.end(), {9, 9, 9});  // unreferenced
  MeshInfo i = mesh_info(m);
  EXPECT_EQ(i.components, 3u);
  EXPECT_EQ(i.unreferenced_vertices, 1u);
  EXPECT_EQ(i.genus, 0);  // sum over components
  EXPECT_EQ(i.euler, 6);
  EXPECT_EQ(i.box.hi[0], 9.0);  // the box includes unreferenced vertices
}

TEST(MeshInfo, SeparateTrianglesAreSeparateLoops) {
  Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 0, 0, 6, 0, 0, 5, 1, 0};
  m.indices = {0, 1, 2, 3, 4, 5};
  MeshInfo i = mesh_info(m);
  EXPECT_EQ(i.components, 2u);
  EXPECT_EQ(i.boundary_loops, 2u);
  EXPECT_EQ(i.boundary_edges, 6u);
}

TEST(MeshInfo, EmptyMesh) {
  MeshInfo i = mesh_info(Mesh{});
  EXPECT_EQ(i.vertices, 0u);
  EXPECT_EQ(i.faces, 0u);
  EXPECT_EQ(i.edges, 0u);
  EXPECT_EQ(i.components, 0u);
  EXPECT_EQ(i.genus, -1);
}

TEST(MeshInfo, IndexOutOfRangeThrows) {
  Mesh m = test::cube();
  m.indices[7] = 8;
  EXPECT_THROW(mesh_info(m), Error);
  try {
    mesh_info(m);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("face 2"), std::string::npos) << e.what();
  }
}

TEST(MeshInfo, FaceOrderDoesNotMatter) {
  Mesh m = welded(test::concatenated(test::cube(), test::transformed(test::cube(), 1, 1, 1, 0)));
  flip_face(m, 3);
  m.indices.insert(m.indices.end(), {0, 1, 1, 2, 3, 0});
  MeshInfo a = mesh_info(m);
  std::vector<std::size_t> order(m.face_count());
  for (std::size_t f = 0; f < order.size(); ++f) order[f] = f;
  std::mt19937 rng(7);
  std::shuffle(order.begin(), order.end(), rng);
  Mesh s = m;
  for (std::size_t f = 0; f < order.size(); ++f)
    for (int k = 0; k < 3; ++k) s.indices[3 * f + k] = m.indices[3 * order[f] + k];
  MeshInfo b = mesh_info(s);
  EXPECT_EQ(a.edges, b.edges);
  EXPECT_EQ(a.boundary_edges, b.boundary_edges);
  EXPECT_EQ(a.boundary_loops, b.boundary_loops);
  EXPECT_EQ(a.non_manifold_edges, b.non_manifold_edges);
  EXPECT_EQ(a.non_manifold_vertices, b.non_manifold_vertices);
  EXPECT_EQ(a.orientation_conflicts, b.orientation_conflicts);
  EXPECT_EQ(a.duplicate_faces, b.duplicate_faces);
  EXPECT_EQ(a.degenerate_faces, b.degenerate_faces);
  EXPECT_EQ(a.components, b.components);
  EXPECT_EQ(a.euler, b.euler);
}

// A million faces, checked for the counts only: mesh_info's speed is BM_MeshInfo's
// (bench/mesh_info_bench.cpp), not a timed unit test's.
TEST(MeshInfo, MillionFaces) {
  const int n = 708;  // 2 * 708^2 = 1,002,528 faces
  const MeshInfo i = mesh_info(test::grid(n));
  EXPECT_EQ(i.faces, 2u * n * n);
  EXPECT_EQ(i.boundary_edges, 4u * n);
  EXPECT_EQ(i.boundary_loops, 1u);
  EXPECT_EQ(i.edges, 2u * n * (n + 1) + std::size_t(n) * n);
  EXPECT_EQ(i.euler, 1);
}

// --- agreement with the catalogue's reference statistics (shared data, skipped when absent) ---------

/// The number stored under "key" in one JSON line of stats.jsonl; nullopt for null or absent.
std::optional<double> json_number(const std::string& line, const std::string& key) {
  std::size_t at = line.find("\"" + key + "\": ");
  if (at == std::string::npos) return std::nullopt;
  const char* p = line.c_str() + at + key.size() + 4;
  char* end = nullptr;
  double v = std::strtod(p, &end);
  if (end == p) return std::nullopt;  // null, true, a string...
  return v;
}

/// The stats.jsonl line of a catalogue file, or "".
std::string catalogue_line(const std::string& file) {
  std::string path = test::shared_data("gen/stats.jsonl");
  if (path.empty()) return "";
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (line.find("\"file\": \"" + file + "\"") != std::string::npos) return line;
  return "";
}

class MeshInfoCatalogue : public testing::TestWithParam<const char*> {};

TEST_P(MeshInfoCatalogue, MatchesReferenceStatistics) {
  const std::string file = GetParam();
  const std::string path = test::shared_data(file);
  const std::string line = catalogue_line(file);
  if (path.empty() || line.empty()) GTEST_SKIP() << file << " or gen/stats.jsonl not in the shared data";
  // The reference tool welds STL by exact position, as load_mesh does by default (Weld::Auto), and
  // counts an OBJ's `v` lines: positions only, not the wedges of its vt/vn corners.
  LoadOptions positions_only;
  positions_only.read_attributes = false;
  MeshInfo i = mesh_info(load_mesh(path, positions_only));
  auto expect = [&](const char* key, double actual) {
    std::optional<double> want = json_number(line, key);
    ASSERT_TRUE(want.has_value()) << key;
    EXPECT_EQ(actual, *want) << file << ": " << key;
  };
  expect("V", double(i.vertices));
  expect("T", double(i.faces));
  expect("unreferenced_V", double(i.unreferenced_vertices));
  expect("E", double(i.edges));
  expect("boundary_E", double(i.boundary_edges));
  expect("boundary_loops", double(i.boundary_loops));
  expect("nonmanifold_E", double(i.non_manifold_edges));
  expect("nonmanifold_V", double(i.non_manifold_vertices));
  expect("components", double(i.components));
  expect("duplicate_T", double(i.duplicate_faces));
  expect("zero_area_T", double(i.zero_area_faces));
  expect("degenerate_T", double(i.degenerate_faces - i.zero_area_faces));  // repeated index only there
  expect("orientation_conflicts", double(i.orientation_conflicts));
  expect("euler", double(i.euler));
  std::optional<double> genus = json_number(line, "genus_sum");
  EXPECT_EQ(i.genus, genus ? (long long)*genus : -1) << file << ": genus";
  std::optional<double> diag = json_number(line, "bbox_diag");
  ASSERT_TRUE(diag.has_value());
  EXPECT_NEAR(i.box.diagonal(), *diag, 1e-6 * (1 + *diag));  // stats round to 6 decimals
}

INSTANTIATE_TEST_SUITE_P(
    SharedData, MeshInfoCatalogue,
    testing::Values("tiny_non_manifold_wrap.obj", "tiny_degenerate_faces.obj", "tiny_isolated_triangles.obj",
                    "tiny_joined_tetrahedra.obj", "tiny_shared_edge_cubes.stl", "tiny_sphere_vcolor.ply",
                    "tiny_soup.stl", "tiny_wallhole_linecont.obj", "tiny_multibody.stl", "gh_cow.obj",
                    "gh_bunny_zipper.ply", "gh_foot_bones.off", "synth_cubes_10x10.ply", "suzanne.obj",
                    "cgal_blobby_shuffled.off", "cgal_b9_mesh.off", "stanford_dragon_vrip_res4.ply",
                    "trimesh_chair.obj", "falconstatue_boundary.obj", "hoppe_mechpart.ply",
                    "cgal_couplingdown.off", "stanford_bunny_soup.stl"),
    [](const testing::TestParamInfo<const char*>& info) {
      std::string name = info.param;
      for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      return name;
    });

}  // namespace
}  // namespace qem
