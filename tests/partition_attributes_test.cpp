// The partitioned run (qem/partition.h) with attributes and materials: each part carries the
// attribute rows of its vertices and the materials of its faces, a seam that crosses a cut is
// locked by position in every part (no crack where the parts met, the seam stays closed), and the
// final pass, refit and attribute fit treat them as simplify does.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <set>

#include "qem/error.h"
#include "qem/measure.h"
#include "qem/partition.h"
#include "qem/simplify.h"
#include "test_meshes.h"

using namespace qem;
using test::open_edges_welded;

namespace {

// 89,400 faces, closed once welded: a UV seam from pole to pole on the half plane y = 0, x >= 0
// (where the 4-part cut of the y axis also runs) and a wedge per segment at each pole.
const Mesh& seamed_sphere() {
  static const Mesh mesh = test::uv_sphere(150, 300);
  return mesh;
}

// 81,920 faces, closed, one vertex per position: smooth colours with a step at z = 0.2 made of
// split vertices (a colour boundary), which the cuts cross.
const Mesh& coloured_sphere() {
  static const Mesh mesh = [] {
    const Mesh sphere = test::icosphere(6);
    Mesh m;
    VertexAttribute colour{"COLOR_0", AttributeKind::Color, 3, {}};
    // A vertex of a face above the step gets a copy of its own: the faces below and above the step
    // meet at a position with two colours.
    std::map<std::uint32_t, std::uint32_t> upper;
    const auto add = [&](std::uint32_t v, bool above) {
      const double* p = &sphere.positions[3 * std::size_t(v)];
      const double r = 1 + 0.05 * std::sin(7 * p[0]) * std::sin(5 * p[1]);
      m.positions.insert(m.positions.end(), {r * p[0], r * p[1], r * p[2]});
      colour.values.insert(colour.values.end(), {0.5 + 0.4 * std::sin(3 * p[0]), 0.5 + 0.4 * p[1], above ? 0.9 : 0.1});
      return std::uint32_t(m.vertex_count() - 1);
    };
    for (std::uint32_t v = 0; v < sphere.vertex_count(); ++v) add(v, false);
    for (std::size_t f = 0; f < sphere.face_count(); ++f) {
      const std::uint32_t* t = &sphere.indices[3 * f];
      const double z = (sphere.positions[3 * std::size_t(t[0]) + 2] + sphere.positions[3 * std::size_t(t[1]) + 2] +
                        sphere.positions[3 * std::size_t(t[2]) + 2]) / 3;
      for (int k = 0; k < 3; ++k) {
        std::uint32_t v = t[k];
        if (z > 0.2) {
          auto [it, fresh] = upper.try_emplace(v, 0);
          if (fresh) it->second = add(v, true);
          v = it->second;
        }
        m.indices.push_back(v);
      }
    }
    m.attributes = {colour};
    return m;
  }();
  return mesh;
}

// 49,152 faces: six sides of 8 x 8 UV charts each (every chart border a seam, flat normals, so
// every cube edge a crease; 64 cells a side, so that the sides meet exactly) and two materials.
const Mesh& material_cube() {
  static const Mesh mesh = test::uv_cube(64, 0.15, true, 8);
  return mesh;
}

// The cube's materials without its attributes (an OBJ with `usemtl` and no `vt`/`vn`).
const Mesh& materials_alone() {
  static const Mesh mesh = [] {
    Mesh m = material_cube();
    m.attributes.clear();
    return m;
  }();
  return mesh;
}

SimplifyOptions ratio(double r, unsigned threads = 2) {
  SimplifyOptions o;
  o.target_ratio = r;
  o.threads = threads;
  o.refit_rounds = 2;  // the command line's default refit
  o.refit_points_per_vertex = 8;
  o.refit_by_reduction = true;
  return o;
}

PartitionOptions in_parts(unsigned parts) {
  PartitionOptions p;
  p.parts = parts;
  return p;
}

struct Case {
  const char* name;
  const Mesh& (*mesh)();
};
const Case kCases[] = {{"seamed sphere", seamed_sphere},
                       {"coloured sphere", coloured_sphere},
                       {"material cube", material_cube},
                       {"materials alone", materials_alone}};

}  // namespace

TEST(PartitionAttributes, ChannelsMaterialsTargetAndNoCrack) {
  for (const Case& c : kCases) {
    const Mesh& in = c.mesh();
    ASSERT_EQ(open_edges_welded(in), 0u) << c.name;
    for (unsigned parts : {2u, 4u}) {
      SCOPED_TRACE(std::string(c.name) + ", " + std::to_string(parts) + " parts");
      PartitionReport report;
      const SimplifyResult r = simplify_partitioned(in, ratio(0.1), in_parts(parts), &report);
      EXPECT_EQ(report.parts, parts);
      EXPECT_GT(report.shared_vertices, 0u);
      const std::size_t target = std::size_t(std::floor(0.1 * double(in.face_count())));
      EXPECT_LE(r.mesh.face_count(), target);
      EXPECT_GE(r.mesh.face_count(), target - 1);
      EXPECT_EQ(r.stop_reason, StopReason::TargetReached);
      // The input's channels, one row per output vertex.
      ASSERT_EQ(r.mesh.attributes.size(), in.attributes.size());
      for (std::size_t a = 0; a < in.attributes.size(); ++a) {
        EXPECT_EQ(r.mesh.attributes[a].name, in.attributes[a].name);
        EXPECT_EQ(r.mesh.attributes[a].kind, in.attributes[a].kind);
        EXPECT_EQ(r.mesh.attributes[a].values.size(), in.attributes[a].components * r.mesh.vertex_count());
      }
      // Welded by position, closed as the input: no crack along a cut, no seam opened.
      EXPECT_EQ(open_edges_welded(r.mesh), 0u);
      EXPECT_EQ(r.output_components, 1u);
      EXPECT_EQ(r.input_components, 1u);
      // Each face keeps its source face's material.
      if (!in.face_materials.empty()) {
        ASSERT_EQ(r.mesh.face_materials.size(), r.mesh.face_count());
        std::set<std::uint32_t> seen;
        for (std::size_t f = 0; f < r.mesh.face_count(); ++f) {
          ASSERT_EQ(r.mesh.face_materials[f], in.face_materials[r.face_source[f]]) << "face " << f;
          seen.insert(r.mesh.face_materials[f]);
        }
        EXPECT_EQ(seen.size(), 2u);
      } else {
        EXPECT_TRUE(r.mesh.face_materials.empty());
      }
      // Attributes keep their meaning: unit normals, colours in range.
      for (const VertexAttribute& a : r.mesh.attributes)
        for (std::size_t v = 0; v < r.mesh.vertex_count(); ++v) {
          const double* x = &a.values[a.components * v];
          if (a.kind == AttributeKind::Normal) {
            ASSERT_NEAR(std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), 1, 1e-9);
          }
          if (a.kind == AttributeKind::Color) {
            for (std::uint32_t k = 0; k < a.components; ++k) ASSERT_TRUE(x[k] >= 0 && x[k] <= 1);
          }
        }
    }
  }
}

// 360,000 faces: the seamed sphere at four times the resolution, with a smooth COLOR_0 besides its
// UVs and normals. The quality bounds are issue 20's (E 1.1x, Hausdorff 1.2x the in-core run's),
// and 1.2x for each attribute's RMS. Measured (2 / 4 parts): E 0.90 / 0.95, Hausdorff 0.91 / 0.66,
// UV RMS 1.00 / 0.78, normals 0.96 / 0.98, colours 0.97 / 0.97. (To 10 %: E 0.96, Hausdorff
// 0.97-0.98, attributes 0.98-1.01, but the UVs in 2 parts 0.04: an outlier of the in-core run's UV
// RMS, not looked into.) On the small meshes above, the cuts' locked strips are a large share of
// each part and the figures scatter more (the 89k-face sphere in 2 parts to 10 %: Hausdorff 1.7x;
// the colour step along a jagged line of faces: colour RMS up to 1.7x; docs/parallel.md).
const Mesh& textured_sphere() {
  static const Mesh mesh = [] {
    Mesh m = test::uv_sphere(300, 600);
    VertexAttribute colour{"COLOR_0", AttributeKind::Color, 3, {}};
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
      const double* p = &m.positions[3 * v];
      colour.values.insert(colour.values.end(), {0.5 + 0.4 * std::sin(3 * p[0]), 0.5 + 0.4 * p[1], 0.5 + 0.4 * std::cos(4 * p[2])});
    }
    m.attributes.push_back(colour);
    return m;
  }();
  return mesh;
}

TEST(PartitionAttributes, ErrorStaysNearTheInCoreRun) {
  const Mesh& in = textured_sphere();
  for (double r : {0.02}) {
    const SimplifyResult whole = simplify(in, ratio(r));
    const MeasureResult e_whole = measure(in, whole.mesh);
    for (unsigned parts : {2u, 4u}) {
      SCOPED_TRACE("ratio " + std::to_string(r) + ", " + std::to_string(parts) + " parts");
      const SimplifyResult split = simplify_partitioned(in, ratio(r), in_parts(parts));
      ASSERT_EQ(split.mesh.face_count(), whole.mesh.face_count());
      const MeasureResult e_split = measure(in, split.mesh);
      EXPECT_LE(e_split.E, 1.1 * e_whole.E);
      EXPECT_LE(e_split.hausdorff, 1.2 * e_whole.hausdorff);
      EXPECT_EQ(e_split.seam_cracks, 0u);
      for (auto field : {&MeasureResult::uv_rms, &MeasureResult::normal_rms_deg, &MeasureResult::color_rms}) {
        ASSERT_TRUE((e_split.*field).has_value());
        ASSERT_TRUE((e_whole.*field).has_value());
        EXPECT_LE(*(e_split.*field), 1.2 * *(e_whole.*field));
      }
    }
  }
}

TEST(PartitionAttributes, SameBytesForAnyThreadCount) {
  for (const Case& c : kCases) {
    const Mesh& in = c.mesh();
    SCOPED_TRACE(c.name);
    SimplifyOptions fit = ratio(0.03, 1);
    fit.fit_attributes = true;  // the attribute fit too
    const SimplifyResult one = simplify_partitioned(in, fit, in_parts(4));
    for (unsigned threads : {2u, 3u}) {
      fit.threads = threads;
      const SimplifyResult r = simplify_partitioned(in, fit, in_parts(4));
      EXPECT_EQ(r.mesh.positions, one.mesh.positions);
      EXPECT_EQ(r.mesh.indices, one.mesh.indices);
      EXPECT_EQ(r.mesh.face_materials, one.mesh.face_materials);
      ASSERT_EQ(r.mesh.attributes.size(), one.mesh.attributes.size());
      for (std::size_t a = 0; a < r.mesh.attributes.size(); ++a)
        EXPECT_EQ(r.mesh.attributes[a].values, one.mesh.attributes[a].values);
    }
  }
}

// The cut is found by position: a part vertex is locked exactly when its position is used by
// another part's faces, whichever wedge those faces use. Found by index, a seam vertex whose two
// wedges each stay on one side of the cut would be locked in neither part.
TEST(PartitionAttributes, TheCutLocksSeamsByPosition) {
  for (const Case& c : kCases) {
    const Mesh& in = c.mesh();
    SCOPED_TRACE(c.name);
    const std::vector<MeshPart> parts = split_mesh(in, ratio(0.1), 4);
    ASSERT_EQ(parts.size(), 4u);
    using Point = std::array<double, 3>;
    const auto at = [&](std::uint32_t v) {
      return Point{in.positions[3 * std::size_t(v)], in.positions[3 * std::size_t(v) + 1], in.positions[3 * std::size_t(v) + 2]};
    };
    std::map<Point, std::set<std::size_t>> parts_at;
    for (std::size_t p = 0; p < parts.size(); ++p)
      for (std::uint32_t g : parts[p].input_vertex) parts_at[at(g)].insert(p);
    std::size_t by_position_only = 0;  // locked although no other part uses this very vertex
    std::vector<int> uses(in.vertex_count(), 0);
    for (const MeshPart& p : parts)
      for (std::uint32_t g : p.input_vertex) ++uses[g];
    for (const MeshPart& p : parts) {
      // The part carries its vertices' rows and its faces' materials (materials alone, with the
      // constant attribute that takes them through the part's run).
      ASSERT_EQ(p.mesh.attributes.size(), in.attributes.size() + (in.attributes.empty() ? 1 : 0));
      for (std::size_t a = 0; a < in.attributes.size(); ++a) {
        const std::uint32_t w = in.attributes[a].components;
        ASSERT_EQ(p.mesh.attributes[a].values.size(), w * p.mesh.vertex_count());
        for (std::size_t l = 0; l < p.input_vertex.size(); ++l)
          for (std::uint32_t k = 0; k < w; ++k)
            ASSERT_EQ(p.mesh.attributes[a].values[w * l + k], in.attributes[a].values[w * p.input_vertex[l] + k]);
      }
      ASSERT_EQ(p.mesh.face_materials.size(), in.face_materials.empty() ? 0 : p.mesh.face_count());
      for (std::size_t f = 0; f < p.mesh.face_materials.size(); ++f)
        ASSERT_EQ(p.mesh.face_materials[f], in.face_materials[p.input_face[f]]);
      for (std::size_t l = 0; l < p.input_vertex.size(); ++l) {
        const bool on_cut = parts_at[at(p.input_vertex[l])].size() > 1;
        ASSERT_EQ(p.locked[l] != 0, on_cut) << "vertex " << p.input_vertex[l];
        by_position_only += on_cut && uses[p.input_vertex[l]] == 1;
      }
    }
    // The seam of the sphere runs along the 4-part cut of the y axis, and the cube's chart borders
    // cross the cuts: there some wedges are on a cut by position only. (The colour step crosses
    // the cuts where the wedge on each side of the step is used by faces of both parts.)
    if (c.mesh != coloured_sphere) {
      EXPECT_GT(by_position_only, 0u);
    }
  }
}

TEST(PartitionAttributes, ProtectedVerticesReachTheParts) {
  const Mesh& in = seamed_sphere();
  std::vector<std::uint8_t> protect(in.vertex_count(), 0);
  for (std::size_t v = 0; v < protect.size(); v += 5) protect[v] = 1;
  SimplifyOptions o = ratio(0.1);
  o.vertex_protect = protect;
  o.seams = SeamMode::Permissive;
  const std::vector<MeshPart> parts = split_mesh(in, o, 2);
  for (const MeshPart& p : parts) {
    ASSERT_EQ(p.protect.size(), p.input_vertex.size());
    for (std::size_t l = 0; l < p.input_vertex.size(); ++l) ASSERT_EQ(p.protect[l], protect[p.input_vertex[l]]);
  }
  const SimplifyResult r = simplify_partitioned(in, o, in_parts(2));
  EXPECT_EQ(open_edges_welded(r.mesh), 0u);
  std::vector<std::uint8_t> short_protect(in.vertex_count() - 1, 0);
  o.vertex_protect = short_protect;
  EXPECT_THROW(split_mesh(in, o, 2), Error);
}
