// Simplification with appearance attributes on wedges (Hoppe 1999): seams stay closed and in
// place, materials never merge, attributes keep their meaning (unit normals, colours in range,
// no bleeding across a step), and a mesh without attributes is untouched by all of it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

#include "qem/error.h"
#include "qem/measure.h"
#include "qem/simplify.h"
#include "test_meshes.h"

using namespace qem;
using test::attribute;
using test::open_edges_welded;
using test::uv_sphere;

TEST(Attributes, UvSeamStaysClosedAndOnItsLine) {
  const Mesh in = uv_sphere(40, 80);
  ASSERT_EQ(open_edges_welded(in), 0u);
  for (Scheme scheme : {Scheme::Passes, Scheme::Greedy}) {
    SimplifyOptions o;
    o.scheme = scheme;
    o.target_ratio = 0.1;
    const SimplifyResult r = simplify(in, o);
    SCOPED_TRACE(to_string(scheme));
    EXPECT_LE(r.mesh.face_count(), in.face_count() / 10 + 2);
    EXPECT_EQ(open_edges_welded(r.mesh), 0u) << "a crack opened";
    const VertexAttribute& uv = attribute(r.mesh, AttributeKind::TexCoord);
    ASSERT_EQ(uv.values.size(), 2 * r.mesh.vertex_count());
    // The seam's vertices (u = 0 or u = 1 in the input) stay on the seam's plane (y = 0, x >= 0)
    // with their u; every u stays in the chart.
    for (std::size_t v = 0; v < r.mesh.vertex_count(); ++v) {
      const double u = uv.values[2 * v];
      EXPECT_GE(u, -1e-9);
      EXPECT_LE(u, 1 + 1e-9);
      const std::uint32_t s = r.vertex_source[v];
      const double su = in.attributes[0].values[2 * s];
      if (su == 0 || su == 1) {
        EXPECT_EQ(r.mesh.positions[3 * v + 1], 0.0) << "seam vertex " << v << " left the seam";
        EXPECT_EQ(u, su);
      }
    }
  }
}

TEST(Attributes, NormalsStayUnitAndWeightsSumToOne) {
  Mesh in = uv_sphere(30, 60);
  VertexAttribute weights{"WEIGHTS_0", AttributeKind::JointWeights, 4, {}};
  VertexAttribute colour{"COLOR_0", AttributeKind::Color, 4, {}};
  for (std::size_t v = 0; v < in.vertex_count(); ++v) {
    const double z = in.positions[3 * v + 2];
    weights.values.insert(weights.values.end(), {0.5 + 0.4 * z, 0.5 - 0.4 * z, 0, 0});
    colour.values.insert(colour.values.end(), {0.5 + 0.5 * z, 0.2, 1.0, 1.0});
  }
  in.attributes.push_back(weights);
  in.attributes.push_back(colour);
  SimplifyOptions o;
  o.target_faces = 300;
  const SimplifyResult r = simplify(in, o);
  ASSERT_EQ(r.mesh.attributes.size(), 4u);
  const VertexAttribute& n = attribute(r.mesh, AttributeKind::Normal);
  const VertexAttribute& w = attribute(r.mesh, AttributeKind::JointWeights);
  const VertexAttribute& c = attribute(r.mesh, AttributeKind::Color);
  for (std::size_t v = 0; v < r.mesh.vertex_count(); ++v) {
    EXPECT_NEAR(std::hypot(n.values[3 * v], n.values[3 * v + 1], n.values[3 * v + 2]), 1.0, 1e-12);
    EXPECT_NEAR(w.values[4 * v] + w.values[4 * v + 1] + w.values[4 * v + 2] + w.values[4 * v + 3], 1.0, 1e-12);
    for (int k = 0; k < 4; ++k) {
      EXPECT_GE(c.values[4 * v + k], 0.0);
      EXPECT_LE(c.values[4 * v + k], 1.0);
    }
  }
}

TEST(Attributes, ColourStepDoesNotBleed) {
  // A flat grid, red left of x = 0.5 and blue right of it, split there into two wedges per
  // position (a colour boundary): simplified hard, no vertex left of the step turns blue.
  const int n = 40;
  Mesh in;
  VertexAttribute colour{"COLOR_0", AttributeKind::Color, 3, {}};
  std::map<std::pair<int, int>, std::uint32_t> left, right;
  auto vertex = [&](int i, int j, bool on_right) {
    auto& side = on_right ? right : left;
    auto [it, fresh] = side.try_emplace({i, j}, std::uint32_t(in.vertex_count()));
    if (fresh) {
      in.positions.insert(in.positions.end(), {double(i) / n, double(j) / n, 0});
      colour.values.insert(colour.values.end(), {on_right ? 0.0 : 1.0, 0.0, on_right ? 1.0 : 0.0});
    }
    return it->second;
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const bool on_right = i >= n / 2;
      const std::uint32_t a = vertex(i, j, on_right), b = vertex(i + 1, j, on_right), c = vertex(i + 1, j + 1, on_right),
                          d = vertex(i, j + 1, on_right);
      in.indices.insert(in.indices.end(), {a, b, c, a, c, d});
    }
  in.attributes = {colour};
  SimplifyOptions o;
  o.target_faces = 16;
  const SimplifyResult r = simplify(in, o);
  EXPECT_LE(r.mesh.face_count(), 40u);
  EXPECT_EQ(open_edges_welded(r.mesh, true), 0u) << "a crack opened along the colour step";
  const VertexAttribute& c = r.mesh.attributes[0];
  for (std::size_t f = 0; f < r.mesh.face_count(); ++f) {
    // Every face is all red or all blue: its corners are on one side of the step.
    std::set<double> reds;  // rounded: a moved vertex's colour is refitted, equal to rounding
    for (int k = 0; k < 3; ++k) reds.insert(std::round(c.values[3 * r.mesh.indices[3 * f + k]] * 1e9));
    EXPECT_EQ(reds.size(), 1u) << "face " << f << " mixes the colours: " << [&] {
      std::string text;
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = r.mesh.indices[3 * f + k];
        text += "(" + std::to_string(r.mesh.positions[3 * v]) + "," + std::to_string(r.mesh.positions[3 * v + 1]) +
                " red " + std::to_string(c.values[3 * v]) + ") ";
      }
      return text;
    }();
  }
  for (std::size_t v = 0; v < r.mesh.vertex_count(); ++v) {
    const double x = r.mesh.positions[3 * v], red = c.values[3 * v];
    if (x < 0.5) {
      EXPECT_NEAR(red, 1.0, 1e-9) << "vertex " << v << " at x = " << x;
    } else if (x > 0.5) {
      EXPECT_NEAR(red, 0.0, 1e-9) << "vertex " << v << " at x = " << x;
    }
  }
}

TEST(Attributes, MaterialsNeverMergeAndTheirBoundaryStays) {
  // With normals, and with materials alone (an OBJ with `usemtl` and no `vt`/`vn`), from a view
  // and from a mesh given away.
  for (int variant = 0; variant < 3; ++variant) {
    SCOPED_TRACE(variant == 0   ? "normals"
                 : variant == 1 ? "materials alone, view"
                                : "materials alone, moved");
    Mesh in =
        test::height_field(30, [](double x, double y) { return 0.05 * std::sin(6 * x) * std::cos(5 * y); });
    if (variant == 0) {
      in.attributes.push_back(
          {"NORMAL", AttributeKind::Normal, 3, std::vector<double>(3 * in.vertex_count(), 0)});
      for (std::size_t v = 0; v < in.vertex_count(); ++v) in.attributes[0].values[3 * v + 2] = 1;
    }
    // Material by the face's centre: left or right of x = 0.5 (a grid line), vertices shared.
    for (std::size_t f = 0; f < in.face_count(); ++f) {
      double cx = 0;
      for (int k = 0; k < 3; ++k) cx += in.positions[3 * in.indices[3 * f + k]] / 3;
      in.face_materials.push_back(cx < 0.5 ? 0 : 1);
    }
    SimplifyOptions o;
    o.target_faces = 60;
    const Mesh copy = in;
    const SimplifyResult r = variant == 2 ? simplify(std::move(in), o) : simplify(in, o);
    EXPECT_LE(r.mesh.face_count(), 60u);
    EXPECT_EQ(r.mesh.attributes.size(), copy.attributes.size());
    ASSERT_EQ(r.mesh.face_materials.size(), r.mesh.face_count());
    std::map<std::array<double, 3>, std::set<std::uint32_t>> materials_at;
    for (std::size_t f = 0; f < r.mesh.face_count(); ++f) {
      EXPECT_EQ(r.mesh.face_materials[f], copy.face_materials[r.face_source[f]]);
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = r.mesh.indices[3 * f + k];
        materials_at[{r.mesh.positions[3 * v], r.mesh.positions[3 * v + 1], r.mesh.positions[3 * v + 2]}]
            .insert(r.mesh.face_materials[f]);
      }
    }
    std::size_t on_both = 0;
    for (const auto& [p, m] : materials_at)
      if (m.size() > 1) {
        ++on_both;
        EXPECT_EQ(p[0], 0.5) << "a point of both materials left the boundary";
      }
    EXPECT_GE(on_both, 2u);
    // Welded by position, no edge along the boundary inside the square is open: no crack.
    std::map<std::array<double, 3>, std::uint32_t> weld;
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    std::vector<std::array<double, 3>> at;
    const auto id = [&](std::uint32_t v) {
      const std::array<double, 3> p{r.mesh.positions[3 * v], r.mesh.positions[3 * v + 1],
                                    r.mesh.positions[3 * v + 2]};
      const auto [it, fresh] = weld.try_emplace(p, std::uint32_t(at.size()));
      if (fresh) at.push_back(p);
      return it->second;
    };
    for (std::size_t f = 0; f < r.mesh.face_count(); ++f)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = id(r.mesh.indices[3 * f + k]), b = id(r.mesh.indices[3 * f + (k + 1) % 3]);
        ++uses[{std::min(a, b), std::max(a, b)}];
      }
    for (const auto& [e, n] : uses) {
      const bool inside = at[e.first][0] == 0.5 && at[e.second][0] == 0.5 && at[e.first][1] > 0 &&
                          at[e.first][1] < 1 && at[e.second][1] > 0 && at[e.second][1] < 1;
      EXPECT_FALSE(inside && n == 1) << "a crack along the boundary";
    }
  }
}

TEST(Attributes, ProvenanceFollowsTheWedges) {
  const Mesh in = uv_sphere(20, 40);
  SimplifyOptions o;
  o.target_ratio = 0.2;
  o.map_input_vertices = true;
  const SimplifyResult r = simplify(in, o);
  ASSERT_EQ(r.vertex_source.size(), r.mesh.vertex_count());
  for (std::uint32_t v = 0; v < r.mesh.vertex_count(); ++v) EXPECT_EQ(r.output_vertex_of_input[r.vertex_source[v]], v);
  for (std::uint32_t f = 0; f < r.mesh.face_count(); ++f)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(r.output_vertex_of_input[in.indices[3 * std::size_t(r.face_source[f]) + k]], r.mesh.indices[3 * f + k]);
}

TEST(Attributes, BadAttributeDataIsRefused) {
  SimplifyOptions to_ten;
  to_ten.target_faces = 10;
  Mesh in = uv_sphere(6, 12);
  in.attributes[0].values[5] = std::nan("");
  EXPECT_THROW(simplify(in, to_ten), Error);
  in = uv_sphere(6, 12);
  in.attributes[1].values.pop_back();
  EXPECT_THROW(simplify(in, to_ten), Error);
  in = uv_sphere(6, 12);
  in.face_materials = {0, 1};
  EXPECT_THROW(simplify(in, to_ten), Error);
}

// A flat grid textured with two charts: the disc of radius 0.3 around (0.5, 0.5) has its own UVs,
// so its outline is a UV seam. Flat and linear in UV on each side, every collapse costs zero in the
// positional and attribute quadrics alike, and only the seam planes (AttributeWeights::seam) see
// that a collapse along the outline cuts the disc's corner off. With them the disc's area stays.
TEST(Attributes, SeamPlanesKeepACurvedSeamsShape) {
  const int n = 60;
  const double r0 = 0.3;
  auto inside = [&](double x, double y) { return std::hypot(x - 0.5, y - 0.5) < r0; };
  Mesh in;
  VertexAttribute uv{"TEXCOORD_0", AttributeKind::TexCoord, 2, {}};
  std::map<std::pair<int, int>, std::uint32_t> vid;  // (grid vertex, chart) -> vertex
  auto vertex = [&](int i, int j, int chart) {
    auto [it, fresh] = vid.try_emplace({i * (n + 1) + j, chart}, std::uint32_t(in.vertex_count()));
    if (fresh) {
      const double x = double(i) / n, y = double(j) / n;
      in.positions.insert(in.positions.end(), {x, y, 0.0});
      uv.values.insert(uv.values.end(), {x + 2 * chart, y});
    }
    return it->second;
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int q[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
      static const int kTriangles[2][3] = {{0, 1, 2}, {0, 2, 3}};
      for (const int* tri : kTriangles) {
        double cx = 0, cy = 0;
        for (int k = 0; k < 3; ++k) cx += q[tri[k]][0] / 3.0 / n, cy += q[tri[k]][1] / 3.0 / n;
        const int chart = inside(cx, cy) ? 1 : 0;
        for (int k = 0; k < 3; ++k) in.indices.push_back(vertex(q[tri[k]][0], q[tri[k]][1], chart));
      }
    }
  in.attributes = {uv};
  auto disc_area = [](const Mesh& m) {
    const std::vector<double>& t = m.attributes[0].values;
    double area = 0;
    for (std::size_t f = 0; f < m.face_count(); ++f) {
      const std::uint32_t* c = &m.indices[3 * f];
      if (t[2 * c[0]] < 1.5) continue;  // the outer chart
      const double* p[3] = {&m.positions[3 * c[0]], &m.positions[3 * c[1]], &m.positions[3 * c[2]]};
      area += std::abs((p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1])) / 2;
    }
    return area;
  };
  const double before = disc_area(in);
  SimplifyOptions o;
  o.target_ratio = 0.1;
  const double with_planes = std::abs(disc_area(simplify(in, o).mesh) / before - 1);
  o.attribute_weights.seam = 0;
  const double without = std::abs(disc_area(simplify(in, o).mesh) / before - 1);
  EXPECT_LT(with_planes, 0.02) << "the disc lost or gained area along its seam";
  EXPECT_LT(with_planes, without) << "seam planes made no difference (without them: " << without << ")";
}

TEST(Attributes, LinearUvsFollowTheMovedVertex) {
  // UVs that are a linear function of the position (u = x, v = y on a wavy height field): Hoppe's
  // optimum at a new position is that function (to second order off the faces' planes), also
  // where the optimal placement leaves the collapsed edge (it does on a curved surface). Clamping
  // them to the box of the two merged ends' UVs pulled such vertices' UVs off it; the box of the
  // neighbours' UVs does not.
  Mesh in =
      test::height_field(24, [](double x, double y) { return 0.1 * std::sin(6 * x) * std::cos(5 * y); });
  VertexAttribute uv{"TEXCOORD_0", AttributeKind::TexCoord, 2, {}};
  for (std::size_t v = 0; v < in.vertex_count(); ++v)
    uv.values.insert(uv.values.end(), {in.positions[3 * v], in.positions[3 * v + 1]});
  in.attributes = {uv};
  SimplifyOptions o;
  o.target_ratio = 0.1;
  o.refit_rounds = 0;    // the refit moves vertices and keeps their values
  o.fit_attributes = false;  // (the default) the fit, tested below, sets values by closest points
  o.lock_border = true;  // the border's vertices would leave the chart, where the box holds them
  const SimplifyResult r = simplify(in, o);
  ASSERT_LE(r.mesh.face_count(), 116u);
  const VertexAttribute& out = attribute(r.mesh, AttributeKind::TexCoord);
  std::set<std::array<double, 3>> grid;  // the input's positions
  for (std::size_t v = 0; v < in.vertex_count(); ++v)
    grid.insert({in.positions[3 * v], in.positions[3 * v + 1], in.positions[3 * v + 2]});
  std::size_t moved = 0;
  double worst = 0;
  for (std::size_t v = 0; v < r.mesh.vertex_count(); ++v) {
    const double x = r.mesh.positions[3 * v], y = r.mesh.positions[3 * v + 1];
    worst = std::max({worst, std::abs(out.values[2 * v] - x), std::abs(out.values[2 * v + 1] - y)});
    moved += !grid.count({x, y, r.mesh.positions[3 * v + 2]});
  }
  EXPECT_GE(moved, 5u) << "the placements did not test what they should";
  // Not exactly: each face's fit is linear within its plane, and a vertex placed off those planes
  // is a second-order distance away (7e-6 here). The endpoints' box gave 0.04, a grid cell.
  EXPECT_LT(worst, 1e-4);
}

TEST(Attributes, FitLowersTheAttributeErrorAndKeepsGeometryAndSeams) {
  // A UV sphere (a seam at u = 0 / 1, poles) with a colour that varies faster than the output's
  // faces: the fit after the run (refit/attribute_fit.h) lowers the colour, normal and UV errors
  // that qem measure reports, and changes nothing else: the same positions and faces, the seam's
  // vertices with their input values.
  Mesh in = uv_sphere(40, 80);
  VertexAttribute colour{"COLOR_0", AttributeKind::Color, 3, {}};
  for (std::size_t v = 0; v < in.vertex_count(); ++v) {
    const double x = in.positions[3 * v], y = in.positions[3 * v + 1], z = in.positions[3 * v + 2];
    colour.values.insert(colour.values.end(), {0.5 + 0.5 * std::sin(7 * x) * std::cos(5 * y), 0.5 + 0.4 * z, 0.2});
  }
  in.attributes.push_back(colour);
  SimplifyOptions o;
  o.target_ratio = 0.1;
  const SimplifyResult before = simplify(in, o);  // the default: no fit
  o.fit_attributes = true;
  const SimplifyResult after = simplify(in, o);
  EXPECT_EQ(after.mesh.positions, before.mesh.positions);
  EXPECT_EQ(after.mesh.indices, before.mesh.indices);
  EXPECT_EQ(open_edges_welded(after.mesh), 0u) << "a crack opened";
  MeasureOptions mo;
  mo.samples = 200000;
  const MeasureResult m0 = measure(in, before.mesh, mo), m1 = measure(in, after.mesh, mo);
  ASSERT_TRUE(m0.color_rms && m1.color_rms && m0.normal_rms_deg && m1.normal_rms_deg && m0.uv_rms && m1.uv_rms);
  EXPECT_LT(*m1.color_rms, 0.95 * *m0.color_rms);
  EXPECT_LE(*m1.uv_rms, *m0.uv_rms);
  // Normals are fitted as vectors and then made unit, which is not the angle the measure takes:
  // on this sphere, whose normals the placement's optimum already gets nearly exact, the fit
  // costs a little (0.081 -> 0.102 degrees); on the shared assets it lowers them
  // (docs/attributes.md). Bounded here so that a fit gone wrong shows.
  EXPECT_LT(*m1.normal_rms_deg, 1.5 * *m0.normal_rms_deg);
  // The seam's vertices (u = 0 or 1 in the input) keep the input's values; the others moved.
  const VertexAttribute& uv_in = attribute(in, AttributeKind::TexCoord);
  const VertexAttribute& c0 = attribute(before.mesh, AttributeKind::Color);
  const VertexAttribute& c1 = attribute(after.mesh, AttributeKind::Color);
  const VertexAttribute& uv1 = attribute(after.mesh, AttributeKind::TexCoord);
  std::size_t seam = 0, changed = 0;
  for (std::size_t v = 0; v < after.mesh.vertex_count(); ++v) {
    const std::uint32_t s = after.vertex_source[v];
    const double su = uv_in.values[2 * s];
    if (su == 0 || su == 1) {
      ++seam;
      EXPECT_EQ(uv1.values[2 * v], su) << "seam vertex " << v;
      for (int k = 0; k < 3; ++k) EXPECT_EQ(c1.values[3 * v + k], c0.values[3 * v + k]) << "seam vertex " << v;
    }
    changed += c1.values[3 * v] != c0.values[3 * v];
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(c1.values[3 * v + k], 0.0);
      EXPECT_LE(c1.values[3 * v + k], 1.0);
    }
  }
  EXPECT_GE(seam, 4u) << "the seam was not tested";
  EXPECT_GE(changed, after.mesh.vertex_count() / 2);
}
