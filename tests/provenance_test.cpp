// Provenance in SimplifyResult: each output vertex's and face's input index, and each input
// vertex's output vertex, which callers use to carry their own per-vertex and per-face data.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "qem/simplify.h"
#include "test_meshes.h"

using namespace qem;

namespace {

Mesh wavy_open_sphere() {
  Mesh m = test::icosphere(4);
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    double* p = &m.positions[3 * v];
    const double r = 1 + 0.07 * std::sin(6 * p[0]) * std::cos(5 * p[1]);
    p[0] *= r, p[1] *= 1.2 * r, p[2] *= 0.9 * r;
  }
  m.indices.resize(m.indices.size() - 3 * 40);  // a hole: border vertices too
  return m;
}

// The three maps agree with each other and with the faces: an output face's corners are the
// output vertices its input face's corners went into, in the same order.
void expect_consistent_provenance(const Mesh& in, const SimplifyResult& r) {
  const Mesh& out = r.mesh;
  ASSERT_EQ(r.vertex_source.size(), out.vertex_count());
  ASSERT_EQ(r.face_source.size(), out.face_count());
  ASSERT_EQ(r.output_vertex_of_input.size(), in.vertex_count());
  std::set<std::uint32_t> sources(r.vertex_source.begin(), r.vertex_source.end());
  EXPECT_EQ(sources.size(), r.vertex_source.size()) << "two output vertices from one input vertex";
  for (std::uint32_t v = 0; v < out.vertex_count(); ++v) {
    ASSERT_LT(r.vertex_source[v], in.vertex_count());
    EXPECT_EQ(r.output_vertex_of_input[r.vertex_source[v]], v) << "output vertex " << v;
  }
  std::set<std::uint32_t> faces(r.face_source.begin(), r.face_source.end());
  EXPECT_EQ(faces.size(), r.face_source.size()) << "two output faces from one input face";
  for (std::uint32_t f = 0; f < out.face_count(); ++f) {
    ASSERT_LT(r.face_source[f], in.face_count());
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(r.output_vertex_of_input[in.indices[3 * std::size_t(r.face_source[f]) + k]], out.indices[3 * f + k])
          << "output face " << f << " corner " << k;
  }
  // Every input vertex of a surviving part went somewhere that is still in the mesh.
  for (std::uint32_t v = 0; v < in.vertex_count(); ++v)
    if (r.output_vertex_of_input[v] != SimplifyResult::kUnmapped) {
      EXPECT_LT(r.output_vertex_of_input[v], out.vertex_count());
    }
}

}  // namespace

TEST(Provenance, MapsAgreeWithTheFacesInEveryOrderAndOption) {
  const Mesh in = wavy_open_sphere();
  for (Scheme scheme : {Scheme::Passes, Scheme::Greedy})
    for (int variant = 0; variant < 4; ++variant) {
      SimplifyOptions o;
      o.scheme = scheme;
      o.greedy_below_faces = 0;
      o.target_ratio = 0.05;
      o.map_input_vertices = true;
      if (variant == 1) o.threshold = 0.05, o.threshold_is_relative = true;
      if (variant == 2) o.refit_rounds = 2;
      if (variant == 3) o.threads = 3;
      SCOPED_TRACE(std::string(to_string(scheme)) + " variant " + std::to_string(variant));
      const SimplifyResult r = simplify(in, o);
      EXPECT_GT(r.contractions, 0u);
      expect_consistent_provenance(in, r);
    }
}

TEST(Provenance, VerticesNothingWentIntoKeepTheirSourcesPositionAndTheMapIsOnlyMadeWhenAsked) {
  const Mesh in = wavy_open_sphere();
  SimplifyOptions o;
  o.target_ratio = 0.3;
  EXPECT_TRUE(simplify(in, o).output_vertex_of_input.empty());
  o.map_input_vertices = true;
  const SimplifyResult r = simplify(in, o);
  std::vector<int> inputs_per_output(r.mesh.vertex_count(), 0);
  for (std::uint32_t v : r.output_vertex_of_input)
    if (v != SimplifyResult::kUnmapped) ++inputs_per_output[v];
  std::size_t untouched = 0;
  for (std::uint32_t v = 0; v < r.mesh.vertex_count(); ++v) {
    if (inputs_per_output[v] != 1) continue;
    ++untouched;
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(r.mesh.positions[3 * v + k], in.positions[3 * std::size_t(r.vertex_source[v]) + k]) << v;
  }
  EXPECT_GT(untouched, 0u);
}

TEST(Provenance, DroppedInputFacesAreCountedAndUnreferencedVerticesUnmapped) {
  Mesh in = test::icosphere(2);
  const std::uint32_t extra = std::uint32_t(in.vertex_count());
  in.positions.insert(in.positions.end(), {5, 5, 5});                            // unreferenced
  in.indices.insert(in.indices.end(), {in.indices[0], in.indices[1], in.indices[0]});  // degenerate
  in.indices.insert(in.indices.end(), {in.indices[5], in.indices[4], in.indices[3]});  // duplicate, flipped
  SimplifyOptions o;
  o.target_faces = 40;
  o.map_input_vertices = true;
  const SimplifyResult r = simplify(in, o);
  EXPECT_EQ(r.dropped_degenerate_faces, 1u);
  EXPECT_EQ(r.dropped_duplicate_faces, 1u);
  EXPECT_EQ(r.input_faces, 320u);
  EXPECT_EQ(r.output_vertex_of_input[extra], SimplifyResult::kUnmapped);
  expect_consistent_provenance(in, r);
}
