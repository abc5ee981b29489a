// Uniform vertex clustering (Rossignac & Borrel 1993; GH97 §2 and Fig. 15) with quadric placement
// of the representatives (Lindstrom 2000). The steps, one function each:
//   grid_of           cell counts and sizes over the bounding box of the referenced vertices
//   assign_clusters   cell key per vertex; clusters numbered in key order (deterministic)
//   place             representative per cluster (quadric minimiser or mean)
//   collapse_faces    faces with 2+ corners in one cluster vanish, duplicates removed
#include "qem/cluster.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "check_mesh.h"
#include "cluster/cluster_quadric.h"
#include "core/quadric.h"
#include "geometry/box.h"
#include "geometry/vec3.h"
#include "qem/error.h"

namespace qem {

namespace {

// 2^21 cells per axis keep the linear cell key within 63 bits.
constexpr std::int64_t kMaxCellsPerAxis = std::int64_t(1) << 21;

struct Grid {
  double lo[3] = {0, 0, 0};
  double size[3] = {0, 0, 0};  ///< cell edge per axis (0 for a flat axis: everything in cell 0)
  std::int64_t n[3] = {1, 1, 1};
  double diag = 0;

  std::int64_t index(int k, double p) const {
    if (!(size[k] > 0)) return 0;
    const double t = std::floor((p - lo[k]) / size[k]);
    return std::clamp<std::int64_t>(std::int64_t(std::clamp(t, 0.0, double(n[k] - 1))), 0, n[k] - 1);
  }
  std::uint64_t key(const double* p) const {
    return (std::uint64_t(index(0, p[0])) * std::uint64_t(n[1]) + std::uint64_t(index(1, p[1]))) *
               std::uint64_t(n[2]) +
           std::uint64_t(index(2, p[2]));
  }
};

Grid grid_of(MeshView mesh, const std::vector<char>& used, const ClusterOptions& o) {
  Grid g;
  BoxOfPoints points;
  for (std::size_t v = 0; v < used.size(); ++v)
    if (used[v]) points.add(&mesh.positions[3 * v]);
  if (points.empty()) return g;  // no faces
  const Box box = points.box();
  double extent[3];
  for (int k = 0; k < 3; ++k) g.lo[k] = box.lo[k], extent[k] = box.hi[k] - box.lo[k];
  g.diag = box.diagonal();
  const bool use_grid = o.grid[0] > 0 && o.grid[1] > 0 && o.grid[2] > 0;
  if (use_grid) {
    for (int k = 0; k < 3; ++k) {
      if (o.grid[k] > kMaxCellsPerAxis)
        throw Error("cluster: grid of " + std::to_string(o.grid[k]) +
                    " cells along an axis is too fine (at most " + std::to_string(kMaxCellsPerAxis) + ")");
      g.n[k] = o.grid[k];
      g.size[k] = extent[k] / double(g.n[k]);
    }
    return g;
  }
  if (o.grid[0] != 0 || o.grid[1] != 0 || o.grid[2] != 0)
    throw Error("cluster: grid cell counts must all be positive, got " + std::to_string(o.grid[0]) + " " +
                std::to_string(o.grid[1]) + " " + std::to_string(o.grid[2]));
  if (!(o.cell > 0) || !std::isfinite(o.cell))
    throw Error("cluster: give a grid (three positive cell counts) or a positive cell size, got cell size " +
                std::to_string(o.cell));
  const double cell = o.cell_relative ? o.cell * g.diag : o.cell;
  for (int k = 0; k < 3; ++k) {
    if (!(extent[k] > 0) || !(cell > 0)) continue;  // flat axis or a single point: one cell
    const double cells = std::ceil(extent[k] / cell);
    if (!(cells <= double(kMaxCellsPerAxis)))
      throw Error("cluster: cell size " + std::to_string(cell) + " gives more than " +
                  std::to_string(kMaxCellsPerAxis) + " cells along an axis");
    g.n[k] = std::max<std::int64_t>(1, std::int64_t(cells));
    g.size[k] = cell;
  }
  return g;
}

/// Cluster id per vertex (UINT32_MAX for unreferenced ones), clusters numbered in cell-key order.
std::vector<std::uint32_t> assign_clusters(MeshView mesh, const std::vector<char>& used, const Grid& g,
                                           std::uint32_t& cluster_count) {
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  for (std::size_t v = 0; v < used.size(); ++v)
    if (used[v]) keyed.emplace_back(g.key(&mesh.positions[3 * v]), std::uint32_t(v));
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> cluster(used.size(), UINT32_MAX);
  cluster_count = 0;
  for (std::size_t i = 0; i < keyed.size(); ++i) {
    if (i > 0 && keyed[i].first != keyed[i - 1].first) ++cluster_count;
    cluster[keyed[i].second] = cluster_count;
  }
  if (!keyed.empty()) ++cluster_count;
  return cluster;
}

/// Representative position per cluster (3 per cluster).
std::vector<double> place(MeshView mesh, const std::vector<std::uint32_t>& cluster, std::uint32_t count,
                          const Grid& g, ClusterPlacement placement) {
  std::vector<double> sum(3 * std::size_t(count), 0.0);
  std::vector<std::uint32_t> members(count, 0);
  for (std::size_t v = 0; v < cluster.size(); ++v) {
    if (cluster[v] == UINT32_MAX) continue;
    for (int k = 0; k < 3; ++k) sum[3 * cluster[v] + k] += mesh.positions[3 * v + k];
    ++members[cluster[v]];
  }
  std::vector<double> out(3 * std::size_t(count));
  for (std::uint32_t c = 0; c < count; ++c)
    for (int k = 0; k < 3; ++k) out[3 * c + k] = sum[3 * c + k] / members[c];
  if (placement == ClusterPlacement::Mean) return out;

  // Lindstrom 2000: each face adds its area-weighted plane quadric to every distinct cluster it
  // touches, including faces that are about to vanish, so the cluster sees all the surface it covers.
  std::vector<core::Quadric> quadric(count);
  const auto point = [&](std::uint32_t v) {
    const double* p = &mesh.positions[3 * std::size_t(v)];
    return Vec3(p[0], p[1], p[2]);
  };
  for (std::size_t f = 0; f < mesh.face_count(); ++f) {
    const std::uint32_t* t = &mesh.indices[3 * f];
    const Vec3 a = point(t[0]);
    const Vec3 n = cross(point(t[1]) - a, point(t[2]) - a);
    const double len = length(n);
    if (!(len > 0)) continue;  // zero-area face: no plane
    // The plane through corner a with unit normal n / len (n.x + d = 0, d = -n.a), weighted by area.
    const Vec3 unit = n / len;
    const core::Quadric plane = core::Quadric::plane(unit, -dot(unit, a), 0.5 * len);
    const std::uint32_t c0 = cluster[t[0]], c1 = cluster[t[1]], c2 = cluster[t[2]];
    quadric[c0] += plane;
    if (c1 != c0) quadric[c1] += plane;
    if (c2 != c0 && c2 != c1) quadric[c2] += plane;
  }
  // Which cell each cluster is, to reject minimisers that leave it (a nearly parallel pair of
  // planes can put the minimiser far away, making a spike): those keep the mean.
  std::vector<std::uint64_t> key(count);
  for (std::size_t v = 0; v < cluster.size(); ++v)
    if (cluster[v] != UINT32_MAX) key[cluster[v]] = g.key(&mesh.positions[3 * v]);
  const double slack = 1e-9 * g.diag;
  for (std::uint32_t c = 0; c < count; ++c) {
    double x[3];
    cluster_detail::minimize_around(quadric[c], &out[3 * c], x);
    std::uint64_t k = key[c];
    const std::int64_t iz = std::int64_t(k % std::uint64_t(g.n[2]));
    k /= std::uint64_t(g.n[2]);
    const std::int64_t iy = std::int64_t(k % std::uint64_t(g.n[1]));
    const std::int64_t ix = std::int64_t(k / std::uint64_t(g.n[1]));
    const std::int64_t idx[3] = {ix, iy, iz};
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      // Cell box widened by half a cell on each side: corners on a cell wall stay representable.
      const double lo = g.lo[a] + (double(idx[a]) - 0.5) * g.size[a] - slack;
      const double hi = g.lo[a] + (double(idx[a]) + 1.5) * g.size[a] + slack;
      inside = inside && std::isfinite(x[a]) && x[a] >= lo && x[a] <= hi;
    }
    if (inside)
      for (int a = 0; a < 3; ++a) out[3 * c + a] = x[a];
  }
  return out;
}

/// Output faces over cluster ids: degenerate ones dropped, duplicates (same three clusters in
/// either orientation) dropped after their first occurrence, input order kept.
std::vector<std::uint32_t> collapse_faces(MeshView mesh, const std::vector<std::uint32_t>& cluster) {
  struct Record {
    std::uint32_t s[3];
    std::uint32_t face;
  };
  std::vector<Record> records;
  for (std::size_t f = 0; f < mesh.face_count(); ++f) {
    const std::uint32_t* t = &mesh.indices[3 * f];
    Record r{{cluster[t[0]], cluster[t[1]], cluster[t[2]]}, std::uint32_t(f)};
    if (r.s[0] == r.s[1] || r.s[1] == r.s[2] || r.s[0] == r.s[2]) continue;
    std::sort(r.s, r.s + 3);
    records.push_back(r);
  }
  std::sort(records.begin(), records.end(), [](const Record& a, const Record& b) {
    return std::lexicographical_compare(a.s, a.s + 3, b.s, b.s + 3) ||
           (std::equal(a.s, a.s + 3, b.s) && a.face < b.face);
  });
  std::vector<char> keep(mesh.face_count(), 0);
  for (std::size_t i = 0; i < records.size(); ++i)
    if (i == 0 || !std::equal(records[i].s, records[i].s + 3, records[i - 1].s)) keep[records[i].face] = 1;
  std::vector<std::uint32_t> faces;
  for (std::size_t f = 0; f < mesh.face_count(); ++f)
    if (keep[f])
      for (int k = 0; k < 3; ++k) faces.push_back(cluster[mesh.indices[3 * f + k]]);
  return faces;
}

}  // namespace

Mesh cluster(MeshView mesh, const ClusterOptions& options) {
  check_mesh(mesh, "cluster");
  std::vector<char> used(mesh.vertex_count(), 0);
  for (std::uint32_t v : mesh.indices) used[v] = 1;
  const Grid grid = grid_of(mesh, used, options);
  std::uint32_t count = 0;
  const std::vector<std::uint32_t> cluster = assign_clusters(mesh, used, grid, count);
  const std::vector<double> rep = place(mesh, cluster, count, grid, options.placement);
  const std::vector<std::uint32_t> faces = collapse_faces(mesh, cluster);

  // Renumber the clusters that are still used, in order of first use (output locality).
  Mesh out;
  std::vector<std::uint32_t> remap(count, UINT32_MAX);
  out.indices.reserve(faces.size());
  for (std::uint32_t c : faces) {
    if (remap[c] == UINT32_MAX) {
      remap[c] = std::uint32_t(out.positions.size() / 3);
      out.positions.insert(out.positions.end(), {rep[3 * c], rep[3 * c + 1], rep[3 * c + 2]});
    }
    out.indices.push_back(remap[c]);
  }
  return out;
}

}  // namespace qem
