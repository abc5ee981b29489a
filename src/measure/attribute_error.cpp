#include "measure/attribute_error.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/parallel_chunks.h"
#include "core/spatial_order.h"
#include "geometry/vec3.h"
#include "measure/point_triangle.h"

namespace qem::measure_detail {

namespace {

/// One compared attribute: its kind, the values compared and what a missing component reads as.
/// The fills follow attr_metric.py: an OBJ `vt u` has v = 0; a colour without alpha (or any
/// channel) reads 1, as its PLY reader and glTF's COLOR_0 VEC3 do.
struct Channel {
  AttributeKind kind;
  unsigned dims;
  double missing;
};
constexpr Channel kChannels[3] = {
    {AttributeKind::TexCoord, 2, 0.0},  // (u, v): a third `w` is ignored, as the script does
    {AttributeKind::Normal, 3, 0.0},
    {AttributeKind::Color, 4, 1.0},  // RGBA
};

const VertexAttribute* find(MeshView mesh, AttributeKind kind) {
  for (const VertexAttribute& a : mesh.attributes)
    if (a.kind == kind) return &a;  // the first of a kind: TEXCOORD_0, COLOR_0
  return nullptr;
}

/// The attribute at barycentric weights `w` of the face with corner vertices `corner`.
void interpolate(const VertexAttribute& a, const Channel& ch, const std::uint32_t* corner, const double w[3],
                 double out[4]) {
  for (unsigned c = 0; c < ch.dims; ++c) {
    if (c >= a.components) {
      out[c] = ch.missing;
      continue;
    }
    double x = 0;
    for (int k = 0; k < 3; ++k) x += w[k] * a.values[std::size_t(corner[k]) * a.components + c];
    out[c] = x;
  }
}

/// The squared error of one channel between two interpolated values: squared distance, or for
/// normals the squared angle in degrees between the normalised directions. The 1e-30 and the clamp
/// are the script's: a zero normal (opposite wedges averaged) reads as 90 degrees, not NaN.
double squared_error(const Channel& ch, const double* x, const double* y) {
  if (ch.kind == AttributeKind::Normal) {
    const double nx = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) + 1e-30;
    const double ny = std::sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]) + 1e-30;
    double c = 0;
    for (int k = 0; k < 3; ++k) c += (x[k] / nx) * (y[k] / ny);
    const double deg = std::acos(std::clamp(c, -1.0, 1.0)) * (180.0 / std::numbers::pi);
    return deg * deg;
  }
  double s = 0;
  for (unsigned k = 0; k < ch.dims; ++k) s += (x[k] - y[k]) * (x[k] - y[k]);
  return s;
}

/// The material of each input face (0 for all when the mesh has none), and their sorted set.
std::vector<std::uint32_t> material_set(MeshView mesh) {
  std::vector<std::uint32_t> set(mesh.face_materials.begin(), mesh.face_materials.end());
  if (set.empty() && mesh.face_count() > 0) set.push_back(0);
  std::sort(set.begin(), set.end());
  set.erase(std::unique(set.begin(), set.end()), set.end());
  return set;
}

std::uint32_t material_of(MeshView mesh, std::uint32_t face) {
  return mesh.face_materials.empty() ? 0 : mesh.face_materials[face];
}

/// A tree to search and how its triangles map to those of `si` (nullptr: the same numbering).
struct Search {
  const TriangleBvh* tree = nullptr;
  const std::vector<std::uint32_t>* to_si = nullptr;
  std::uint32_t triangle(std::uint32_t t) const { return to_si ? (*to_si)[t] : t; }
};

/// Trees over the faces of each material of `si`, the script's rule when both meshes have the same
/// material set: a sample on the original's leather is compared with the approximation's leather,
/// not with the metal that came closer.
struct MaterialTrees {
  std::vector<std::uint32_t> materials;  ///< sorted; tree g holds material materials[g]
  std::vector<TriangleBvh> trees;
  std::vector<std::vector<std::uint32_t>> to_si;
  std::size_t group(std::uint32_t material) const {
    return std::size_t(std::lower_bound(materials.begin(), materials.end(), material) - materials.begin());
  }
};

MaterialTrees material_trees(MeshView approx, const Surface& si, std::vector<std::uint32_t> materials) {
  MaterialTrees m;
  m.materials = std::move(materials);
  const std::size_t ng = m.materials.size();
  std::vector<std::vector<double>> corners(ng);
  m.to_si.resize(ng);
  for (std::size_t t = 0; t < si.triangle_count(); ++t) {
    const std::size_t g = m.group(material_of(approx, si.face_of[t]));
    corners[g].insert(corners[g].end(), &si.corners[9 * t], &si.corners[9 * t + 9]);
    m.to_si[g].push_back(std::uint32_t(t));
  }
  m.trees.resize(ng);
  for (std::size_t g = 0; g < ng; ++g) m.trees[g] = TriangleBvh(corners[g]);
  return m;
}

/// The face to read the approximation's attributes from, given `t`, the closest face to `p` that
/// `search` found (lowest index of equally close faces). When the closest point is on an edge or a
/// corner, the faces around it are all as close: on a convex hull of the original, whole wedges of
/// samples land on edges, so the choice decides what a seam reads (u = 0 or u = 1). The lowest
/// index is arbitrary; this takes the face the sample lies most squarely over, the largest
/// |cos| between the face normal and the offset to its closest point, the side of the seam the
/// sample is on. (The script's Embree queries, in float, pick that side nearly always: 3 of 199
/// edge hits by the seam of the test's UV sphere went across, against ~half by lowest index.)
std::uint32_t settle_tie(const Surface& si, const Search& search, const double* p, std::uint32_t t,
                         std::vector<std::uint32_t>& scratch) {
  auto corner = [&](std::uint32_t tri, int k) {
    const double* c = &si.corners[9 * std::size_t(tri) + 3 * k];
    return Vec3{c[0], c[1], c[2]};
  };
  const Vec3 q{p[0], p[1], p[2]};
  const std::array<double, 3> w = closest_point_weights(q, corner(t, 0), corner(t, 1), corner(t, 2));
  if (w[0] > 0 && w[1] > 0 && w[2] > 0) return t;  // inside the face: no other face is as close
  const double d2 =
      squared_distance(q, closest_point_on_triangle(q, corner(t, 0), corner(t, 1), corner(t, 2)));
  if (!(d2 > 0)) return t;               // on the surface: no direction to judge by
  const double limit = d2 * (1 + 1e-9);  // the same edge point, reached through another face's rounding
  scratch.clear();
  search.tree->within(p, limit, scratch);
  std::uint32_t best = t;
  double best_cos = -1;
  for (const std::uint32_t id : scratch) {
    const std::uint32_t u = search.triangle(id);
    const Vec3 a = corner(u, 0), b = corner(u, 1), c = corner(u, 2);
    const Vec3 offset = q - closest_point_on_triangle(q, a, b, c);
    const double e2 = dot(offset, offset);
    if (e2 > limit) continue;
    const Vec3 n = cross(b - a, c - a);
    const double cosine = std::abs(dot(n, offset)) / std::sqrt(dot(n, n) * e2);
    if (cosine > best_cos || (cosine == best_cos && u < best)) best_cos = cosine, best = u;
  }
  return best;
}

}  // namespace

bool has_comparable_attributes(MeshView original, MeshView approx) {
  for (const Channel& ch : kChannels)
    if (find(original, ch.kind) && find(approx, ch.kind)) return true;
  return false;
}

AttributeErrors attribute_errors(MeshView original, const Surface& sn, MeshView approx, const Surface& si,
                                 const TriangleBvh& tree_i, const std::vector<double>& samples,
                                 const std::vector<SamplePlace>& places,
                                 const std::vector<std::uint32_t>& hits_all, unsigned threads) {
  AttributeErrors result;
  const std::size_t n = places.size();
  std::vector<std::uint32_t> materials = material_set(original);
  MaterialTrees by_material;
  if (materials.size() > 1 && materials == material_set(approx)) {
    result.by_material = true;
    by_material = material_trees(approx, si, std::move(materials));
  }
  // Each sample's search: the whole approximation (whose answers the distance pass found), or the
  // faces of its material; a material without a face of non-zero area there falls back to all
  // faces, as the script does for a group without faces.
  const Search everything{&tree_i, nullptr};
  auto search_of = [&](std::size_t k) {
    if (!result.by_material) return everything;
    const std::size_t g = by_material.group(material_of(original, sn.face_of[places[k].triangle]));
    if (by_material.trees[g].empty()) return everything;
    return Search{&by_material.trees[g], &by_material.to_si[g]};
  };
  // Queries in Morton order within fixed chunks; no answer depends on the warm start or the chunk,
  // so the faces, and the sums below, are the same for any thread count.
  std::vector<std::uint32_t> hits(n);
  const std::vector<std::uint32_t> order = core::morton_order(
      n, [&](std::size_t i) { return Vec3(samples[3 * i], samples[3 * i + 1], samples[3 * i + 2]); });
  core::for_chunks(n, kQueryChunk, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    std::uint32_t hint = UINT32_MAX;
    const TriangleBvh* last = nullptr;
    std::vector<std::uint32_t> scratch;
    for (std::size_t j = begin; j < end; ++j) {
      const std::uint32_t k = order[j];
      const Search search = search_of(k);
      std::uint32_t t = hits_all[k];
      if (search.tree != &tree_i) {
        if (search.tree != last)
          hint = UINT32_MAX, last = search.tree;  // a hint names a triangle of one tree
        t = search.triangle(search.tree->closest(&samples[3 * k], &hint).triangle);
      }
      hits[k] = settle_tie(si, search, &samples[3 * k], t, scratch);
    }
  });

  std::optional<double>* out[3] = {&result.uv_rms, &result.normal_rms_deg, &result.color_rms};
  for (int c = 0; c < 3; ++c) {
    const Channel& ch = kChannels[c];
    const VertexAttribute* an = find(original, ch.kind);
    const VertexAttribute* ai = find(approx, ch.kind);
    if (!an || !ai) continue;
    // Each error goes to its slot and the sum runs in sample order: the same bits for any thread count.
    std::vector<double> e2(n);
    core::for_chunks(n, kQueryChunk, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) {
        double x[4], y[4];
        interpolate(*an, ch, &original.indices[3 * std::size_t(sn.face_of[places[k].triangle])], places[k].w,
                    x);
        const std::uint32_t t = hits[k];
        const double* tc = &si.corners[9 * std::size_t(t)];
        const std::array<double, 3> w =
            closest_point_weights({samples[3 * k], samples[3 * k + 1], samples[3 * k + 2]},
                                  {tc[0], tc[1], tc[2]}, {tc[3], tc[4], tc[5]}, {tc[6], tc[7], tc[8]});
        interpolate(*ai, ch, &approx.indices[3 * std::size_t(si.face_of[t])], w.data(), y);
        e2[k] = squared_error(ch, x, y);
      }
    });
    double sum = 0;
    for (const double e : e2) sum += e;
    *out[c] = n ? std::sqrt(sum / double(n)) : 0.0;
  }
  return result;
}

std::size_t welded_boundary_edges(MeshView mesh) {
  const std::size_t nv = mesh.vertex_count();
  const double* P = mesh.positions.data();
  // Lexicographic order on (x, y, z) with `<`, so -0 and +0 are one position, as in numpy's unique.
  auto less = [P](std::uint32_t a, std::uint32_t b) {
    for (int k = 0; k < 3; ++k) {
      if (P[3 * std::size_t(a) + k] < P[3 * std::size_t(b) + k]) return true;
      if (P[3 * std::size_t(b) + k] < P[3 * std::size_t(a) + k]) return false;
    }
    return false;
  };
  std::vector<std::uint32_t> order(nv);
  for (std::size_t v = 0; v < nv; ++v) order[v] = std::uint32_t(v);
  std::sort(order.begin(), order.end(), less);
  std::vector<std::uint32_t> weld(nv);
  std::uint32_t id = 0;
  for (std::size_t i = 0; i < nv; ++i) {
    if (i > 0 && less(order[i - 1], order[i])) ++id;
    weld[order[i]] = id;
  }
  std::vector<std::uint64_t> edges;
  edges.reserve(mesh.indices.size());
  for (std::size_t f = 0; f < mesh.face_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = weld[mesh.indices[3 * f + k]], b = weld[mesh.indices[3 * f + (k + 1) % 3]];
      if (a == b) continue;  // an edge collapsed by welding is no edge (the script drops it too)
      edges.push_back(std::uint64_t(std::min(a, b)) << 32 | std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  std::size_t boundary = 0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    boundary += (j - i == 1);
    i = j;
  }
  return boundary;
}

}  // namespace qem::measure_detail
