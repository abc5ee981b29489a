// Connected components kept by default (src/core/component_guard.h), the prune rule, and a face
// target of 0 ("as far as the checks allow").
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <string>

#include "qem/error.h"
#include "qem/io.h"
#include "qem/mesh_info.h"
#include "qem/simplify.h"
#include "test_meshes.h"

using namespace qem;

namespace {

// 100 separate parts on a 10 x 10 lattice with spacing 3: even ones an open bumpy patch (a 6 x 6
// height field, 72 faces), odd ones a closed icosphere (320 faces); sizes vary from 0.2 to 1.1,
// so the small ones are the cheapest to contract away. `small_first` parts (of the 100) get size
// 0.02 instead. Returns the mesh and, per part, its first face.
struct Parts {
  Mesh mesh;
  std::vector<std::size_t> first_face;  // 101 entries: part i is [first_face[i], first_face[i + 1])
};

double bumps(double x, double y) { return 0.1 * x * (1 - x) * y * (1 - y) * 16; }

Parts hundred_parts(int small_first = 0) {
  Parts p;
  const Mesh patch = test::height_field(6, bumps), ball = test::icosphere(2);
  for (int i = 0; i < 100; ++i) {
    const double size = i < small_first ? 0.02 : 0.2 + 0.9 * double((i * 37) % 100) / 99.0;
    const Mesh part =
        test::transformed(i % 2 == 0 ? patch : ball, size, 3.0 * (i % 10), 3.0 * (i / 10), 0.1 * i);
    p.first_face.push_back(p.mesh.face_count());
    p.mesh = i == 0 ? part : test::concatenated(p.mesh, part);
  }
  p.first_face.push_back(p.mesh.face_count());
  return p;
}

// Components as the simplifier counts them: on the welded positions (with attributes an output
// position may carry several vertices, one per wedge).
std::size_t components(const Mesh& m) {
  std::map<std::array<double, 3>, std::uint32_t> first;
  Mesh welded;
  welded.positions = m.positions;
  for (std::uint32_t i : m.indices) {
    const std::array<double, 3> p{m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]};
    welded.indices.push_back(first.emplace(p, i).first->second);
  }
  return mesh_info(welded).components;
}

SimplifyOptions low_target(Scheme scheme, unsigned threads) {
  SimplifyOptions o;
  o.target_faces = 50;  // below one face per part: unreachable while every part stays
  o.scheme = scheme;
  o.threads = threads;
  o.greedy_below_faces = 0;  // passes (and their threads) to the end
  // GH97's border penalty: under exact borders (the default) a patch's four corners are kept, so
  // the patches could never contract away and the guard would have nothing to do.
  o.exact_border = false;
  return o;
}

}  // namespace

TEST(Components, HundredPartsKeptAtALowTargetInBothOrdersAndOnTwoThreads) {
  const Parts parts = hundred_parts();
  ASSERT_EQ(components(parts.mesh), 100u);
  Mesh one_thread;
  for (Scheme scheme : {Scheme::Greedy, Scheme::Passes}) {
    for (unsigned threads : {1u, 2u}) {
      SCOPED_TRACE(std::string(to_string(scheme)) + " threads " + std::to_string(threads));
      const SimplifyResult r = simplify(parts.mesh, low_target(scheme, threads));
      EXPECT_EQ(r.input_components, 100u);
      EXPECT_EQ(r.output_components, 100u);
      EXPECT_EQ(components(r.mesh), 100u);
      EXPECT_EQ(r.stop_reason, StopReason::NoValidPair);
      EXPECT_GT(r.rejected_component, 0u);
      EXPECT_NE(r.stop_detail.find("to keep components"), std::string::npos) << r.stop_detail;
      // Each open patch keeps at least 1 face, each closed ball at least 4.
      EXPECT_GE(r.mesh.face_count(), 50u * 1 + 50u * 4);
      // The same output on 1 and 2 threads.
      if (threads == 1) {
        one_thread = r.mesh;
      } else {
        EXPECT_EQ(r.mesh.indices, one_thread.indices);
        EXPECT_EQ(r.mesh.positions, one_thread.positions);
      }
    }
  }
}

TEST(Components, WithoutTheGuardSmallPartsVanish) {
  // What the guard prevents (GH97 as published): the open patches contract to nothing.
  const Parts parts = hundred_parts();
  for (Scheme scheme : {Scheme::Greedy, Scheme::Passes}) {
    SimplifyOptions o = low_target(scheme, 1);
    o.keep_components = false;
    const SimplifyResult r = simplify(parts.mesh, o);
    EXPECT_LT(components(r.mesh), 100u) << to_string(scheme);
    EXPECT_EQ(r.output_components, components(r.mesh));
    EXPECT_EQ(r.rejected_component, 0u);
  }
}

TEST(Components, InputCountedWithAndWithoutTheGuardAndBelowTheTarget) {
  // The guard counts the input's parts when it runs; otherwise, and when the input is already at
  // the target (no guard is made), they are counted on their own: the same count every way.
  const Parts parts = hundred_parts();
  for (bool keep : {true, false})
    for (std::size_t target : {std::size_t(50), parts.mesh.face_count()}) {
      SimplifyOptions o = low_target(Scheme::Passes, 1);
      o.keep_components = keep;
      o.target_faces = target;
      const SimplifyResult r = simplify(parts.mesh, o);
      EXPECT_EQ(r.input_components, 100u) << keep << " " << target;
      EXPECT_EQ(r.stop_reason == StopReason::AlreadyBelowTarget, target == parts.mesh.face_count());
    }
}

TEST(Components, AtTenPercentEveryPartStays) {
  const Parts parts = hundred_parts();
  for (unsigned threads : {1u, 2u}) {
    SimplifyOptions o;
    o.target_ratio = 0.1;
    o.threads = threads;
    o.greedy_below_faces = 0;
    const SimplifyResult r = simplify(parts.mesh, o);
    EXPECT_EQ(r.stop_reason, StopReason::TargetReached);
    EXPECT_EQ(components(r.mesh), 100u);
  }
}

TEST(Components, ThresholdPairsJoinPartsIntoOne) {
  // Two cubes 0.05 apart joined by t = 0.1 (GH97 §3.2): from the first threshold contraction on
  // they are one component, which keeps its floor as a whole.
  const Mesh two = test::concatenated(test::cube(), test::transformed(test::cube(), 1, 1.05, 0, 0));
  SimplifyOptions o;
  o.as_far_as_possible = true;
  o.threshold = 0.1;
  o.preserve_topology = false;  // no link condition: only the guard holds the parts
  const SimplifyResult r = simplify(two, o);
  EXPECT_EQ(r.input_components, 2u);
  EXPECT_EQ(r.output_components, 1u);  // joined, then held at the closed floor as one part
  EXPECT_EQ(r.mesh.face_count(), 4u);
  EXPECT_GT(r.rejected_component, 0u);
  o.keep_components = false;  // GH97 as published: the joined parts contract to nothing
  EXPECT_EQ(simplify(two, o).mesh.face_count(), 0u);
}

TEST(Components, PruneRemovesExactlyThePartsBelowTheSize) {
  // The first 30 parts have a diagonal of 0.02 * sqrt(2) (patches) or 0.04 (balls); the others
  // at least 0.2 * sqrt(2). A prune size of 0.1 removes exactly the 30.
  const Parts parts = hundred_parts(30);
  for (bool relative : {false, true}) {
    SCOPED_TRACE(relative ? "relative" : "absolute");
    SimplifyOptions o;
    o.target_ratio = 0.5;
    o.map_input_vertices = true;
    o.prune_size = 0.1;
    if (relative) {
      o.prune_size /= mesh_info(parts.mesh).box.diagonal();
      o.prune_size_is_relative = true;
    }
    const SimplifyResult r = simplify(parts.mesh, o);
    EXPECT_EQ(r.input_components, 100u);
    EXPECT_EQ(r.pruned_components, 30u);
    EXPECT_EQ(r.output_components, 70u);
    EXPECT_EQ(components(r.mesh), 70u);
    for (std::uint32_t f : r.face_source) EXPECT_GE(f, parts.first_face[30]);
    // The pruned parts' vertices map nowhere; every other part is still there.
    const std::uint32_t first_kept_vertex = parts.mesh.indices[3 * parts.first_face[30]];
    for (std::uint32_t v = 0; v < first_kept_vertex; ++v)
      EXPECT_EQ(r.output_vertex_of_input[v], SimplifyResult::kUnmapped);
    // The ratio is of the input's faces, before pruning.
    EXPECT_EQ(r.input_faces, parts.mesh.face_count());
    EXPECT_LE(r.mesh.face_count(), parts.mesh.face_count() / 2);
  }
}

TEST(Components, PruneSizeMustBeAFiniteDistance) {
  SimplifyOptions o;
  o.target_ratio = 0.5;
  o.prune_size = -1;
  EXPECT_THROW(check_options(o), Error);
  o.prune_size = std::numeric_limits<double>::infinity();
  EXPECT_THROW(check_options(o), Error);
}

TEST(FacesZero, AsFarAsPossibleStopsWhereTheChecksStop) {
  const Parts parts = hundred_parts();
  for (Scheme scheme : {Scheme::Greedy, Scheme::Passes}) {
    SCOPED_TRACE(to_string(scheme));
    SimplifyOptions o;
    o.as_far_as_possible = true;
    o.scheme = scheme;
    const SimplifyResult r = simplify(parts.mesh, o);
    EXPECT_EQ(r.stop_reason, StopReason::NoValidPair);
    EXPECT_EQ(components(r.mesh), 100u);
    // Where it stopped, no contraction passes the checks: a second run makes none.
    const SimplifyResult again = simplify(r.mesh, o);
    EXPECT_EQ(again.contractions, 0u);
    EXPECT_EQ(again.mesh.indices, r.mesh.indices);
  }
}

TEST(FacesZero, TheOtherCriteriaStillApply) {
  SimplifyOptions o;
  o.as_far_as_possible = true;
  o.max_error = 1e-3;
  const SimplifyResult r = simplify(test::icosphere(3), o);
  EXPECT_EQ(r.stop_reason, StopReason::ErrorLimit);
  EXPECT_LE(r.max_error, 1e-3);
  SimplifyOptions none;
  EXPECT_THROW(check_options(none), Error);  // no criterion at all is still refused
}

TEST(FacesZero, CommandLineReadsZeroAsFarAsTheChecksAllow) {
  const std::string dir = test::temp_dir();
  const std::string in = dir + "/parts.ply", out = dir + "/parts_0.ply";
  save_mesh(in, hundred_parts().mesh);
  for (const char* stop : {"--faces 0", "--ratio 0", "--vertices 0"}) {
    SCOPED_TRACE(stop);
    ASSERT_EQ(
        test::run_qem_quietly("simplify " + in + " " + out + " " + std::string(stop) + " --no-refit --forget 0 --force"),
        0);
    SimplifyOptions o;
    o.as_far_as_possible = true;
    const SimplifyResult r = simplify(load_mesh(in), o);
    EXPECT_EQ(load_mesh(out).indices, r.mesh.indices);
  }
  // qem lod takes a level of 0 faces too: the last level is the mesh as far as the checks allow.
  EXPECT_EQ(test::run_qem_quietly("lod " + in + " " + dir + "/lod --faces 0,2000 --no-refit"), 0);
  SimplifyOptions all_the_way;
  all_the_way.as_far_as_possible = true;
  const std::size_t last_faces = simplify(load_mesh(in), all_the_way).mesh.face_count();
  EXPECT_NE(test::slurp(dir + "/lod/manifest.json").find("\"faces\": " + std::to_string(last_faces)),
            std::string::npos);
  // The summary's JSON line counts the components.
  const std::string cmd =
      std::string(QEM_CLI_PATH) + " simplify " + in + " " + out + " --faces 0 --json -q --force";
  FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string json;
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), pipe)) json.append(buf.data(), n);
  EXPECT_EQ(pclose(pipe), 0);
  EXPECT_NE(json.find("\"in_components\":100,\"out_components\":100,\"pruned_components\":0"),
            std::string::npos)
      << json;
}

// The multi-component meshes of ../shared/data at t = 0 keep their component count at 10 % and
// 1 % of their faces (where a target is below what the parts' floors allow, the run stops there:
// "no valid contraction left"). The counts are the catalogue's (../shared/data/README.md);
// trimesh_busted.stl is one component once welded, as STL is on read.
TEST(Components, CorpusMultiComponentMeshesKeepTheirCount) {
  const std::pair<const char*, std::size_t> meshes[] = {
      {"gh_foot_bones.off", 26}, {"synth_cubes_10x10.ply", 100}, {"trimesh_busted.stl", 1},
      {"tiny_multibody.stl", 2}, {"hoppe_cessna.ply", 11},       {"ogre.obj", 44},
      {"igl_truck.obj", 50},     {"cgal_b9_mesh.off", 47},       {"trimesh_cycloidal.ply", 100}};
  for (const auto& [name, count] : meshes) {
    const std::string path = test::shared_data(name);
    if (path.empty()) GTEST_SKIP() << "../shared/data not found";
    const Mesh in = load_mesh(path);
    for (double ratio : {0.1, 0.01}) {
      SCOPED_TRACE(std::string(name) + " ratio " + std::to_string(ratio));
      SimplifyOptions o;
      o.target_ratio = ratio;
      const SimplifyResult r = simplify(in, o);
      EXPECT_EQ(r.input_components, count);
      EXPECT_EQ(r.output_components, count);
      EXPECT_EQ(components(r.mesh), count);
      EXPECT_TRUE(r.stop_reason == StopReason::TargetReached || r.stop_reason == StopReason::NoValidPair)
          << r.stop_detail;
    }
  }
}
