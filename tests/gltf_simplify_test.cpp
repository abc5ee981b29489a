// simplify_document (qem/gltf_simplify.h) and `qem simplify` / `qem lod` on glTF documents built in
// code: the shared error budget in world units, the per-mesh mode, primitives that must be kept,
// and inputs that must be refused with no output written.
#include "qem/gltf_simplify.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "qem/error.h"
#include "qem/gltf.h"
#include "qem/measure.h"
#include "test_meshes.h"

namespace {

using json = nlohmann::json;

/// A glTF document assembled in code: meshes of float POSITION (+ NORMAL) and uint32 indices,
/// each placed by a node with a uniform scale, one embedded buffer.
struct Scene {
  json doc = json::parse(R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": []}],
                             "nodes": [], "meshes": [], "accessors": [], "bufferViews": [],
                             "buffers": [{"byteLength": 0}]})");
  std::string bin;

  int accessor(const std::vector<float>& values, const char* type, std::size_t count, bool bounds) {
    const std::size_t offset = bin.size();
    bin.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", values.size() * 4}});
    json a = {{"bufferView", doc["bufferViews"].size() - 1},
              {"componentType", 5126},
              {"count", count},
              {"type", type}};
    if (bounds) {
      std::vector<float> lo(3, 1e30f), hi(3, -1e30f);
      for (std::size_t i = 0; i < values.size(); ++i)
        lo[i % 3] = std::min(lo[i % 3], values[i]), hi[i % 3] = std::max(hi[i % 3], values[i]);
      a["min"] = lo, a["max"] = hi;
    }
    doc["accessors"].push_back(a);
    return int(doc["accessors"].size() - 1);
  }
  int indices(const std::vector<std::uint32_t>& idx) {
    const std::size_t offset = bin.size();
    bin.append(reinterpret_cast<const char*>(idx.data()), idx.size() * 4);
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", idx.size() * 4}});
    doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1},
                                {"componentType", 5125},
                                {"count", idx.size()},
                                {"type", "SCALAR"}});
    return int(doc["accessors"].size() - 1);
  }
  /// A mesh of one primitive; normals from the positions' direction (a sphere's).
  int mesh(const qem::Mesh& m, bool normals = true) {
    std::vector<float> p(m.positions.begin(), m.positions.end()), n;
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
      const double* q = &m.positions[3 * v];
      const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
      for (int c = 0; c < 3; ++c) n.push_back(float(q[c] / len));
    }
    json prim = {{"attributes", {{"POSITION", accessor(p, "VEC3", m.vertex_count(), true)}}}};
    if (normals) prim["attributes"]["NORMAL"] = accessor(n, "VEC3", m.vertex_count(), false);
    prim["indices"] = indices(m.indices);
    doc["meshes"].push_back({{"primitives", json::array({prim})}});
    return int(doc["meshes"].size() - 1);
  }
  void node(int mesh, double scale) {
    doc["nodes"].push_back({{"mesh", mesh}, {"scale", {scale, scale, scale}}});
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
  }
  std::string text() const { return qem::test::gltf_text(doc, bin); }
};

/// Two spheres of 5120 faces: a unit one at scale 1 and one of local radius 0.1 drawn at scale 100
/// (world radius 10). In its own units the second is tiny; in the world it is the big one.
Scene two_spheres() {
  Scene s;
  s.node(s.mesh(qem::test::icosphere(4)), 1);
  s.node(s.mesh(qem::test::transformed(qem::test::icosphere(4), 0.1, 0, 0, 0)), 100);
  return s;
}

/// 200 separate tetrahedra of 0.05 (800 faces, which no contraction may touch: each would lose its
/// topology) in one mesh, and a unit sphere of 5120 faces in another.
Scene dead_end_scene() {
  Scene s;
  qem::Mesh tetras;
  for (int k = 0; k < 200; ++k)
    tetras = qem::test::concatenated(
        tetras, qem::test::transformed(qem::test::tetrahedron(), 0.05, k % 20, k / 20.0, 0));
  s.node(s.mesh(tetras, false), 1);
  s.node(s.mesh(qem::test::icosphere(4)), 1);
  return s;
}

TEST(GltfSimplify, WorldScaleFollowsTheNodes) {
  Scene s = two_spheres();
  s.node(1, 30);  // the second mesh instanced again, smaller: its largest scale counts
  qem::GltfDocument doc = qem::GltfDocument::parse(s.text(), "two.gltf");
  EXPECT_DOUBLE_EQ(doc.primitives()[0].world_scale, 1);
  EXPECT_NEAR(doc.primitives()[1].world_scale, 100, 1e-9);
}

TEST(GltfSimplify, SharedBudgetStopsEveryPrimitiveAtTheSameWorldError) {
  qem::GltfDocument doc = qem::GltfDocument::parse(two_spheres().text(), "two.gltf");
  qem::SimplifyOptions opt;
  opt.target_ratio = 0.1;
  const qem::GltfSimplifyReport r = qem::simplify_document(doc, opt);
  ASSERT_EQ(r.primitives.size(), 2u);
  EXPECT_EQ(r.simplified, 2u);
  EXPECT_EQ(r.faces_in, 2 * 5120u);
  EXPECT_EQ(r.target_faces, 1024u);
  EXPECT_LE(r.faces_out, 1024u);
  EXPECT_GT(r.faces_out, 900u);  // the threshold is the smallest that meets the target
  const qem::GltfPrimitiveOutcome &small = r.primitives[0], &big = r.primitives[1];
  // The big sphere (in the world) keeps more of its faces than the small one.
  EXPECT_GT(big.faces_out, 2 * small.faces_out);
  // Both stop at the threshold: every contraction made is within it, and the next one is beyond
  // it, or the primitive stopped on the step that reaches it. The primitive whose contraction set
  // the threshold stops there exactly.
  bool at_threshold = false;
  for (const auto* o : {&small, &big}) {
    EXPECT_LE(o->world_error, r.world_threshold * (1 + 1e-12));
    const bool on_step = std::fabs(o->world_error - r.world_threshold) <= 1e-12 * r.world_threshold;
    at_threshold = at_threshold || on_step;
    if (!on_step) {
      EXPECT_GT(o->next_world_error, r.world_threshold);
    }
    EXPECT_NEAR(o->world_error, o->max_error * o->world_scale, 1e-12 * o->world_error);
  }
  EXPECT_TRUE(at_threshold);
  EXPECT_EQ(doc.primitives()[0].face_count, small.faces_out);
  EXPECT_EQ(doc.primitives()[1].face_count, big.faces_out);
  // Normals came through the simplification with the positions, of unit length.
  const qem::Mesh m = doc.mesh(1);
  ASSERT_EQ(m.attributes.size(), 1u);
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    const double* n = &m.attributes[0].values[3 * v];
    EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1, 1e-6);
  }
}

TEST(GltfSimplify, PerMeshModeAppliesTheRatioToEachPrimitive) {
  qem::GltfDocument doc = qem::GltfDocument::parse(two_spheres().text(), "two.gltf");
  qem::SimplifyOptions opt;
  opt.target_ratio = 0.1;
  qem::GltfSimplifyOptions per;
  per.per_primitive = true;
  const qem::GltfSimplifyReport r = qem::simplify_document(doc, opt, per);
  for (const qem::GltfPrimitiveOutcome& o : r.primitives) {
    EXPECT_EQ(o.status, qem::GltfPrimitiveOutcome::Status::Simplified);
    EXPECT_LE(o.faces_out, 512u);
    EXPECT_GT(o.faces_out, 480u);
  }
  // The same shape at ten times the world size: ten times the world error.
  EXPECT_NEAR(r.primitives[1].world_error / r.primitives[0].world_error, 10, 0.5);
}

TEST(GltfSimplify, OutputDoesNotDependOnThreads) {
  std::string bytes[2];
  for (unsigned threads : {1u, 2u}) {
    qem::GltfDocument doc = qem::GltfDocument::parse(two_spheres().text(), "two.gltf");
    qem::SimplifyOptions opt;
    opt.target_ratio = 0.2;
    qem::GltfSimplifyOptions g;
    g.threads = threads;
    qem::simplify_document(doc, opt, g);
    bytes[threads - 1] = doc.serialize(true);
  }
  EXPECT_EQ(bytes[0], bytes[1]);
}

TEST(GltfSimplify, WorldErrorLimitIsSharedToo) {
  qem::GltfDocument doc = qem::GltfDocument::parse(two_spheres().text(), "two.gltf");
  qem::SimplifyOptions opt;
  opt.max_error = 0.01;  // world units
  const qem::GltfSimplifyReport r = qem::simplify_document(doc, opt);
  EXPECT_EQ(r.simplified, 2u);
  for (const qem::GltfPrimitiveOutcome& o : r.primitives) {
    EXPECT_LE(o.world_error, 0.01);
    EXPECT_GT(o.world_error, 0.005);
  }
}

TEST(GltfSimplify, DistanceBoundIsInWorldUnits) {
  // The second sphere has local radius 0.1 and is drawn 100 times larger: a world bound of 0.02 is
  // 0.0002 in its units. Measured independently (qem::measure, in local units, times the scale),
  // no primitive's output lies farther than the bound from its input in the world.
  qem::GltfDocument doc = qem::GltfDocument::parse(two_spheres().text(), "two.gltf");
  std::vector<qem::Mesh> before;
  for (std::size_t i = 0; i < 2; ++i) before.push_back(doc.mesh(i));
  qem::SimplifyOptions opt;
  opt.max_distance = 0.02;
  const qem::GltfSimplifyReport r = qem::simplify_document(doc, opt);
  EXPECT_EQ(r.simplified, 2u);
  EXPECT_GT(r.max_world_distance, 0);
  EXPECT_LE(r.max_world_distance, 0.02);
  qem::MeasureOptions mo;
  mo.seed = 3;
  for (std::size_t i = 0; i < 2; ++i) {
    const qem::GltfPrimitiveOutcome& o = r.primitives[i];
    const double world = qem::measure(before[i], doc.mesh(i), mo).h_approx_to_original * o.world_scale;
    EXPECT_LE(world, 0.02) << "primitive " << i;
    EXPECT_LE(o.world_distance, 0.02);
    EXPECT_LT(o.faces_out, o.faces_in);  // the bound is a stop criterion, not a freeze
  }
  // The big sphere (world radius 10) keeps far more faces than the unit one under the same bound.
  EXPECT_GT(r.primitives[1].faces_out, 2 * r.primitives[0].faces_out);
}

TEST(GltfSimplify, VertexTargetIsTheSameFractionOfTheFaces) {
  qem::GltfDocument doc = qem::GltfDocument::parse(two_spheres().text(), "two.gltf");
  const std::size_t vertices = doc.primitives()[0].vertex_count + doc.primitives()[1].vertex_count;
  qem::SimplifyOptions opt;
  opt.target_vertices = vertices / 5;
  const qem::GltfSimplifyReport r = qem::simplify_document(doc, opt);
  EXPECT_EQ(r.target_faces, std::size_t(10240.0 * double(vertices / 5) / double(vertices)));
  EXPECT_LE(r.faces_out, r.target_faces);
  EXPECT_GT(r.faces_out, r.target_faces * 9 / 10);
}

TEST(GltfSimplify, PrimitivesAtADeadEndLeaveTheReductionToTheOthers) {
  // 200 separate tetrahedra: no contraction keeps their topology, so their 800 faces stay; the
  // sphere must then go below the watched run's floor (a quarter of the scene's ratio) to come
  // as close to the target as it can.
  qem::GltfDocument doc = qem::GltfDocument::parse(dead_end_scene().text(), "dead_end.gltf");
  qem::SimplifyOptions opt;
  opt.target_ratio = 0.1;  // 592 of 5920 faces
  const qem::GltfSimplifyReport r = qem::simplify_document(doc, opt);
  EXPECT_EQ(r.primitives[0].faces_out, 800u);
  EXPECT_LT(r.primitives[1].faces_out, 128u);  // 0.25 x 0.1 x 5120, the first floor
  EXPECT_EQ(r.primitives[1].stop_reason, qem::StopReason::NoValidPair);
}

/// A unit sphere of 5120 faces split into primitives of one mesh (materials), each with its own
/// copy of the vertices on the lines where they meet, as exporters write them: face f goes to
/// primitive part_of(centroid z). Primitive k gets TEXCOORD_0 (u = x, v = y) when uvs[k].
Scene split_sphere(const std::function<int(double)>& part_of, int parts, std::vector<bool> uvs = {}) {
  const qem::Mesh sphere = qem::test::icosphere(4);
  Scene s;
  s.doc["meshes"].push_back({{"primitives", json::array()}});
  for (int k = 0; k < parts; ++k) {
    qem::Mesh part;
    std::vector<std::uint32_t> id(sphere.vertex_count(), UINT32_MAX);
    for (std::size_t f = 0; f < sphere.face_count(); ++f) {
      double z = 0;
      for (int c = 0; c < 3; ++c) z += sphere.positions[3 * sphere.indices[3 * f + c] + 2] / 3;
      if (part_of(z) != k) continue;
      for (int c = 0; c < 3; ++c) {
        std::uint32_t& v = id[sphere.indices[3 * f + c]];
        if (v == UINT32_MAX) {
          v = std::uint32_t(part.vertex_count());
          const double* p = &sphere.positions[3 * sphere.indices[3 * f + c]];
          part.positions.insert(part.positions.end(), {p[0], p[1], p[2]});
        }
        part.indices.push_back(v);
      }
    }
    const int m = s.mesh(part);
    json prim = s.doc["meshes"][m]["primitives"][0];
    if (k < int(uvs.size()) && uvs[k]) {
      std::vector<float> uv;
      for (std::size_t v = 0; v < part.vertex_count(); ++v)
        uv.push_back(float(part.positions[3 * v])), uv.push_back(float(part.positions[3 * v + 1]));
      prim["attributes"]["TEXCOORD_0"] = s.accessor(uv, "VEC2", part.vertex_count(), false);
    }
    s.doc["meshes"][0]["primitives"].push_back(prim);
    s.doc["meshes"].erase(m);
  }
  s.node(0, 1);
  return s;
}

/// The positions that primitives 0 and 1 (of the document) both have.
std::size_t shared_positions(const qem::GltfDocument& doc) {
  std::set<std::array<double, 3>> first;
  const qem::Mesh a = doc.mesh(0), b = doc.mesh(1);
  for (std::size_t v = 0; v < a.vertex_count(); ++v)
    first.insert({a.positions[3 * v], a.positions[3 * v + 1], a.positions[3 * v + 2]});
  std::set<std::array<double, 3>> both;
  for (std::size_t v = 0; v < b.vertex_count(); ++v) {
    const std::array<double, 3> p{b.positions[3 * v], b.positions[3 * v + 1], b.positions[3 * v + 2]};
    if (first.count(p)) both.insert(p);
  }
  return both.size();
}

/// A document of two primitives that meet (split_sphere's halves) simplified to 10 %, in the shared
/// budget or per mesh: both primitives simplified, to under a fifth, and no crack between them.
qem::GltfDocument halves_to_a_tenth(const std::string& text, bool per_mesh) {
  qem::GltfDocument doc = qem::GltfDocument::parse(text, "halves.gltf");
  qem::SimplifyOptions opt;
  opt.target_ratio = 0.1;
  qem::GltfSimplifyOptions gltf_options;
  gltf_options.per_primitive = per_mesh;
  const qem::GltfSimplifyReport r = qem::simplify_document(doc, opt, gltf_options);
  EXPECT_EQ(r.simplified, 2u);
  EXPECT_LT(r.faces_out, r.faces_in / 5);
  EXPECT_EQ(qem::test::open_edges_welded(doc.scene_mesh()), 0u) << "a crack opened between the primitives";
  return doc;
}

/// halves_to_a_tenth in the shared budget, then per mesh: the line where the halves meet (`line`
/// shared positions) is simplified in the first and kept as it is in the second. Both documents.
std::array<qem::GltfDocument, 2> halves_in_both_modes(const std::string& text, std::size_t line) {
  std::array<qem::GltfDocument, 2> docs;
  for (bool per_mesh : {false, true}) {
    SCOPED_TRACE(per_mesh ? "per mesh" : "shared budget");
    qem::GltfDocument& doc = docs[per_mesh ? 1 : 0];
    doc = halves_to_a_tenth(text, per_mesh);
    if (per_mesh)
      EXPECT_EQ(shared_positions(doc), line);
    else
      EXPECT_LT(shared_positions(doc), line);
  }
  return docs;
}

TEST(GltfSimplify, PrimitivesOfOneMeshStayJoined) {
  // Two halves of a sphere. Simplified apart, each would move or remove its side of the line where
  // they meet: a crack. With the shared budget they are simplified as one surface (the line a seam
  // whose sides collapse together), so the line is simplified too; per mesh, each keeps its side
  // of the line as it is. Welded by position, the output is as closed as the input either way.
  // The upper half has texture coordinates, the lower none (merged, it holds zeros there, and it is
  // written back without them).
  const Scene s = split_sphere([](double z) { return z > 0.3 ? 0 : 1; }, 2, {true, false});
  const qem::GltfDocument input = qem::GltfDocument::parse(s.text(), "halves.gltf");
  ASSERT_EQ(qem::test::open_edges_welded(input.scene_mesh()), 0u);
  const std::size_t line = shared_positions(input);
  ASSERT_GT(line, 20u);
  for (const qem::GltfDocument& doc : halves_in_both_modes(s.text(), line)) {
    EXPECT_EQ(doc.mesh(0).attributes.size(), 2u);  // NORMAL, TEXCOORD_0
    EXPECT_EQ(doc.mesh(1).attributes.size(), 1u);  // NORMAL
  }
}

/// The primitives of `doc` (one mesh) as one mesh of Draco-compressed primitives, each with its
/// positions quantized to `bits` bits in its own box (as gltf-transform and Blender write them).
std::string draco_halves(const qem::GltfDocument& doc, int bits) {
  json out = {{"asset", {{"version", "2.0"}}},
              {"extensionsUsed", {"KHR_draco_mesh_compression"}},
              {"extensionsRequired", {"KHR_draco_mesh_compression"}},
              {"scene", 0},
              {"scenes", {{{"nodes", {0}}}}},
              {"nodes", {{{"mesh", 0}}}},
              {"meshes", {{{"primitives", json::array()}}}},
              {"accessors", json::array()},
              {"bufferViews", json::array()},
              {"buffers", {{{"byteLength", 0}}}}};
  std::string bin;
  for (std::size_t k = 0; k < doc.primitives().size(); ++k) {
    const qem::Mesh m = doc.mesh(k);
    const std::string stream = qem::test::draco_bitstream(m, bits);
    out["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", stream.size()}});
    bin += stream;
    bin.resize((bin.size() + 3) & ~std::size_t(3), '\0');
    std::vector<double> lo(3, 1e30), hi(3, -1e30);
    for (std::size_t i = 0; i < m.positions.size(); ++i)
      lo[i % 3] = std::min(lo[i % 3], m.positions[i]), hi[i % 3] = std::max(hi[i % 3], m.positions[i]);
    const std::size_t a = out["accessors"].size();
    out["accessors"].push_back(
        {{"componentType", 5126}, {"count", m.vertex_count()}, {"type", "VEC3"}, {"min", lo}, {"max", hi}});
    out["accessors"].push_back({{"componentType", 5125}, {"count", m.indices.size()}, {"type", "SCALAR"}});
    out["meshes"][0]["primitives"].push_back(
        {{"attributes", {{"POSITION", a}}},
         {"indices", a + 1},
         {"extensions",
          {{"KHR_draco_mesh_compression",
            {{"bufferView", out["bufferViews"].size() - 1}, {"attributes", {{"POSITION", 0}}}}}}}});
  }
  return qem::test::gltf_text(out, bin);
}

TEST(GltfSimplify, DracoCompressedPrimitivesStayJoined) {
  // Draco quantizes each primitive in its own box: decoded, the halves of a sphere no longer meet
  // at equal positions (cracks a grid step wide). They are joined within the grids' steps, so the
  // scene is closed, and so is the output, in both modes.
  const Scene s = split_sphere([](double z) { return z > 0.3 ? 0 : 1; }, 2);
  const std::string text = draco_halves(qem::GltfDocument::parse(s.text(), "halves.gltf"), 11);
  const qem::GltfDocument input = qem::GltfDocument::parse(text, "draco.gltf");
  ASSERT_EQ(input.primitives().size(), 2u);
  for (const qem::GltfPrimitiveInfo& p : input.primitives()) {
    const qem::Mesh m = input.mesh(p.primitive);
    std::array<double, 3> lo{1e30, 1e30, 1e30}, hi{-1e30, -1e30, -1e30};
    for (std::size_t i = 0; i < m.positions.size(); ++i)
      lo[i % 3] = std::min(lo[i % 3], m.positions[i]), hi[i % 3] = std::max(hi[i % 3], m.positions[i]);
    const double range = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
    EXPECT_NEAR(p.position_step, range / 2047, 1e-6 * range);
  }
  const std::size_t line = shared_positions(qem::GltfDocument::parse(s.text(), "halves.gltf"));
  ASSERT_LT(shared_positions(input), line / 2) << "the decoded halves should not meet exactly";
  // The scene merged (load_mesh, qem measure, glTF to another format) joins them too.
  EXPECT_EQ(qem::test::open_edges_welded(input.scene_mesh()), 0u);
  for (bool per_mesh : {false, true}) {
    SCOPED_TRACE(per_mesh ? "per mesh" : "shared budget");
    const qem::GltfDocument doc = halves_to_a_tenth(text, per_mesh);
    EXPECT_GT(shared_positions(doc), 4u);
  }
}

TEST(GltfSimplify, MeshesThatTheSameNodesDrawStayJoined) {
  // An exporter that splits one object into a mesh per material puts each under its own node
  // (Sketchfab's downloads: Object_0, Object_1, ... under one parent). Drawn by the same world
  // matrices, the halves of a sphere in two meshes are joined as two primitives of one mesh are;
  // a mesh drawn by other matrices too is another object.
  Scene s = split_sphere([](double z) { return z > 0.3 ? 0 : 1; }, 2);
  const json second = s.doc["meshes"][0]["primitives"][1];
  s.doc["meshes"][0]["primitives"].erase(1);
  s.doc["meshes"].push_back({{"primitives", json::array({second})}});
  s.node(1, 1);  // as split_sphere's node for mesh 0
  const qem::GltfDocument input = qem::GltfDocument::parse(s.text(), "two_meshes.gltf");
  ASSERT_EQ(input.primitives().size(), 2u);
  EXPECT_EQ(input.primitives()[0].placement, 0u);
  EXPECT_EQ(input.primitives()[1].placement, 0u);
  const std::size_t line = shared_positions(input);
  ASSERT_GT(line, 20u);
  halves_in_both_modes(s.text(), line);
  s.node(1, 3);  // mesh 1 drawn a second time, three times larger
  const qem::GltfDocument apart = qem::GltfDocument::parse(s.text(), "two_meshes.gltf");
  EXPECT_EQ(apart.primitives()[0].placement, 0u);
  EXPECT_EQ(apart.primitives()[1].placement, 1u);
}

TEST(GltfSimplify, MergedPrimitiveThatWouldVanishIsKept) {
  // CesiumMilkTruck's body, glass and window trim are one mesh of three primitives whose borders
  // meet. Merged and simplified with permissive seams to 1 %, the trim (six frames between the body
  // and the glass) closes up entirely; it is kept as it was then (the run made again with its
  // vertices locked), the body and glass simplified round it, and no crack opens. (With the normal
  // weight of a 1 % output's spacing, normal_per_spacing, the trim keeps a few faces unlocked: the
  // fixed weight is the case that closes it.)
  const std::string path = qem::test::shared_data("CesiumMilkTruck.glb");
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  qem::GltfDocument doc = qem::GltfDocument::load(path);
  const std::size_t trim = doc.mesh(2).face_count();
  const std::size_t open = qem::test::open_edges_welded(doc.scene_mesh());
  qem::SimplifyOptions opt;
  opt.target_ratio = 0.01;
  opt.seams = qem::SeamMode::Permissive;
  opt.attribute_weights.normal_per_spacing = 0;
  const qem::GltfSimplifyReport r = qem::simplify_document(doc, opt, {});
  EXPECT_EQ(r.simplified, 4u);
  EXPECT_EQ(doc.mesh(2).face_count(), trim);
  EXPECT_LT(doc.mesh(0).face_count(), 200u);
  EXPECT_LE(qem::test::open_edges_welded(doc.scene_mesh()), open);
}

TEST(GltfSimplify, MorphTargetsFollowTheSimplification) {
  Scene s = two_spheres();
  // Mesh 0 gets a morph target whose offsets are its normals' accessor: on the unit sphere each
  // vertex's offset is its position, a linear field that the attribute fit reproduces at any place.
  s.doc["meshes"][0]["primitives"][0]["targets"] = json::array({{{"POSITION", 1}}});
  s.doc["meshes"][0]["weights"] = {0.5};
  qem::GltfDocument doc = qem::GltfDocument::parse(s.text(), "morph.gltf");
  EXPECT_TRUE(doc.primitives()[0].simplifiable);
  qem::SimplifyOptions opt;
  opt.target_ratio = 0.2;
  const qem::GltfSimplifyReport r = qem::simplify_document(doc, opt);
  EXPECT_EQ(r.simplified, 2u);
  EXPECT_LT(r.primitives[0].faces_out, 5120u);
  const json out = json::parse(doc.serialize(false));
  const json& p = out["meshes"][0]["primitives"][0];
  ASSERT_EQ(p["targets"].size(), 1u);
  const json& offsets = out["accessors"][p["targets"][0]["POSITION"].get<int>()];
  const json& positions = out["accessors"][p["attributes"]["POSITION"].get<int>()];
  EXPECT_EQ(offsets["count"], positions["count"]);
  EXPECT_TRUE(offsets.contains("min") && offsets.contains("max"));  // glTF requires them on POSITION
  EXPECT_EQ(out["meshes"][0]["weights"], json::array({0.5}));
  const qem::GltfDocument again = qem::GltfDocument::parse(doc.serialize(true), "again.glb");
  const qem::Mesh m = again.mesh(0);
  const qem::VertexAttribute* target = nullptr;
  for (const qem::VertexAttribute& a : m.attributes)
    if (a.name == "target0/POSITION") target = &a;
  ASSERT_TRUE(target);
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    EXPECT_NEAR(target->values[i], m.positions[i], 1e-5) << i;
}

// --- through the command line -------------------------------------------------------------------

std::string write(const std::string& path, const std::string& bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  std::fwrite(bytes.data(), 1, bytes.size(), f);
  std::fclose(f);
  return path;
}

/// Runs `qem ARGS`, stderr to a file; gives the exit status and the stderr text.
int run_qem(const std::string& args, std::string* err) {
  const std::string log = qem::test::temp_dir() + "/stderr.txt";
  const int status =
      std::system((std::string(QEM_CLI_PATH) + " " + args + " > /dev/null 2> '" + log + "'").c_str());
  *err = qem::test::slurp(log);
  return status;
}

TEST(GltfSimplifyCli, KeepsTheDocumentAndNotesKeptPrimitives) {
  Scene s = two_spheres();
  s.doc["meshes"][0]["primitives"][0]["mode"] = 1;  // lines: kept as they are
  s.doc["nodes"][0]["extras"] = {{"tag", "kept"}};
  const std::string dir = qem::test::temp_dir();
  const std::string in = write(dir + "/lines.gltf", s.text()), out = dir + "/out.glb";
  std::string err;
  ASSERT_EQ(run_qem("simplify '" + in + "' '" + out + "' --ratio 0.2", &err), 0) << err;
  EXPECT_NE(err.find("mode 1 is not TRIANGLES"), std::string::npos) << err;
  EXPECT_NE(err.find("1 simplified"), std::string::npos) << err;
  qem::GltfDocument doc = qem::GltfDocument::load(out);
  EXPECT_EQ(doc.primitives()[0].mode, 1);
  EXPECT_LE(doc.primitives()[1].face_count, 1024u);
  EXPECT_FALSE(doc.primitives()[0].simplifiable);
  // --json: the counts, and each primitive.
  const std::string out_json = dir + "/out.json";
  ASSERT_EQ(std::system((std::string(QEM_CLI_PATH) + " simplify '" + in + "' '" + out +
                         "' --ratio 0.2 --json -q > '" + out_json + "' 2> /dev/null")
                            .c_str()),
            0);
  const json report = json::parse(qem::test::slurp(out_json));
  EXPECT_EQ(report["format"], "gltf");
  EXPECT_EQ(report["simplified"], 1);
  EXPECT_EQ(report["kept"], 1);
  EXPECT_EQ(report["in_faces"], 5120);
  EXPECT_EQ(report["out_faces"].get<std::size_t>(), doc.primitives()[1].face_count);
  ASSERT_EQ(report["each"].size(), 2u);
  EXPECT_EQ(report["each"][0]["status"], "kept");
  EXPECT_EQ(report["each"][1]["status"], "simplified");
  EXPECT_EQ(report["each"][1]["out_faces"].get<std::size_t>(), doc.primitives()[1].face_count);
  EXPECT_NEAR(report["each"][1]["world_scale"].get<double>(), 100, 1e-9);
  // --per-mesh on a non-glTF output is refused.
  EXPECT_NE(run_qem("simplify '" + in + "' '" + dir + "/x.ply' --ratio 0.5 --per-mesh", &err), 0);
  EXPECT_NE(err.find("--per-mesh"), std::string::npos) << err;
}

TEST(GltfSimplifyCli, AsFarAsPossibleIsNoMissedTarget) {
  // --faces 0 asks every primitive to go as far as the checks allow: stopping where no contraction
  // is left is what was asked, not a target missed. With a target that a dead end keeps the scene
  // from (200 tetrahedra that no contraction may touch, and a sphere), the summary says it missed.
  Scene s = two_spheres();
  const std::string dir = qem::test::temp_dir();
  const std::string in = write(dir + "/far.gltf", s.text()), out = dir + "/far_out.glb";
  std::string err;
  ASSERT_EQ(run_qem("simplify '" + in + "' '" + out + "' --faces 0", &err), 0) << err;
  EXPECT_EQ(err.find("stopped before"), std::string::npos) << err;
  EXPECT_NE(err.find("2 primitives went as far as the checks allow"), std::string::npos) << err;
  const std::string out_json = dir + "/far.json";
  ASSERT_EQ(std::system((std::string(QEM_CLI_PATH) + " simplify '" + in + "' '" + out +
                         "' --faces 0 --json -q > '" + out_json + "' 2> /dev/null")
                            .c_str()),
            0);
  const json report = json::parse(qem::test::slurp(out_json));
  EXPECT_EQ(report["stopped_early"], 0);
  EXPECT_EQ(report["target_faces"], 0);
  for (const json& each : report["each"]) EXPECT_EQ(each["stop"], "no valid contraction left");

  const std::string in2 = write(dir + "/dead_end.gltf", dead_end_scene().text());
  ASSERT_EQ(run_qem("simplify '" + in2 + "' '" + out + "' --ratio 0.1 --force", &err), 0) << err;
  EXPECT_NE(err.find("1 primitive stopped before the scene's target"), std::string::npos) << err;
  ASSERT_EQ(run_qem("simplify '" + in2 + "' '" + out + "' --faces 0 --force", &err), 0) << err;
  EXPECT_EQ(err.find("stopped before"), std::string::npos) << err;
}

TEST(GltfSimplifyCli, CompressedGeometryThatCannotBeDecodedGivesNoOutput) {
  Scene s = two_spheres();
  s.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  s.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  s.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"] = {
      {"bufferView", 0}, {"attributes", {{"POSITION", 0}}}};  // view 0 holds floats, not a bitstream
  const std::string dir = qem::test::temp_dir();
  const std::string in = write(dir + "/draco.gltf", s.text()), out = dir + "/draco_out.glb";
  std::string err;
  EXPECT_NE(run_qem("simplify '" + in + "' '" + out + "' --ratio 0.5", &err), 0);
  EXPECT_NE(err.find("draco.gltf: mesh 0, primitive 0: the Draco data in buffer view 0 cannot be decoded"),
            std::string::npos)
      << err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(GltfSimplifyCli, AccessorOutOfRangeIsAnErrorWithNoOutput) {
  Scene s = two_spheres();
  s.doc["accessors"][3]["count"] = 1000000;  // mesh 1's POSITION, far beyond its buffer view
  const std::string dir = qem::test::temp_dir();
  const std::string in = write(dir + "/bad.gltf", s.text()), out = dir + "/bad_out.glb";
  std::string err;
  EXPECT_NE(run_qem("simplify '" + in + "' '" + out + "' --ratio 0.5", &err), 0);
  EXPECT_NE(err.find("bad.gltf: mesh 1, primitive 0 (POSITION), accessor 3"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_NE(run_qem("lod '" + in + "' '" + dir + "/lods' --ratios 0.5", &err), 0);
  EXPECT_FALSE(std::filesystem::exists(dir + "/lods/bad_lod0.glb"));
}

TEST(GltfLodCli, OneWholeDocumentPerLevel) {
  Scene s = two_spheres();
  s.doc["nodes"][1]["name"] = "big";
  const std::string dir = qem::test::temp_dir();
  const std::string in = write(dir + "/two.gltf", s.text());
  std::string err;
  ASSERT_EQ(run_qem("lod '" + in + "' '" + dir + "/lods' --ratios 0.5,0.1", &err), 0) << err;
  const json manifest = json::parse(qem::test::slurp(dir + "/lods/manifest.json"));
  ASSERT_EQ(manifest["levels"].size(), 2u);
  std::size_t previous = 10240;
  for (std::size_t i = 0; i < 2; ++i) {
    const std::string file = manifest["levels"][i]["path"];
    EXPECT_EQ(file, "two_lod" + std::to_string(i) + ".glb");
    qem::GltfDocument level = qem::GltfDocument::load(dir + "/lods/" + file);
    ASSERT_EQ(level.primitives().size(), 2u);
    const std::size_t faces = level.primitives()[0].face_count + level.primitives()[1].face_count;
    EXPECT_EQ(faces, manifest["levels"][i]["faces"].get<std::size_t>());
    EXPECT_LE(faces, i == 0 ? 5120u : 1024u);
    EXPECT_LT(faces, previous);
    previous = faces;
    // The same as `qem simplify --faces <target>` writes.
    const std::string single = dir + "/single" + std::to_string(i) + ".glb";
    ASSERT_EQ(run_qem("simplify '" + in + "' '" + single + "' --faces " +
                          std::to_string(manifest["levels"][i]["target_faces"].get<std::size_t>()),
                      &err),
              0)
        << err;
    EXPECT_EQ(qem::test::slurp(single), qem::test::slurp(dir + "/lods/" + file)) << i;
  }
  // --format gltf writes .gltf levels; a non-glTF input cannot give glTF levels.
  ASSERT_EQ(run_qem("lod '" + in + "' '" + dir + "/text' --ratios 0.5 --format gltf", &err), 0) << err;
  EXPECT_EQ(qem::GltfDocument::load(dir + "/text/two_lod0.gltf").primitives().size(), 2u);
  const std::string ply = dir + "/sphere.ply";
  ASSERT_EQ(run_qem("generate sphere '" + ply + "' --faces 1000", &err), 0) << err;
  EXPECT_NE(run_qem("lod '" + ply + "' '" + dir + "/p' --ratios 0.5 --format glb", &err), 0);
  EXPECT_NE(err.find("glTF levels are made from a glTF input"), std::string::npos) << err;
}

}  // namespace
