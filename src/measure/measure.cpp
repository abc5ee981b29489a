// GH97 §6.1 evaluation metric: E_i over area-uniform samples of both surfaces, plus Hausdorff,
// RMS and mean distance. The distance queries run on std::threads over fixed-size chunks whose
// partial sums are combined in chunk order, so the result is bit-identical for any thread count.
#include "qem/measure.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "core/parallel_chunks.h"
#include "core/spatial_order.h"
#include "geometry/box.h"
#include "geometry/vec3.h"
#include "measure/attribute_error.h"
#include "measure/bvh.h"
#include "measure/surface_sampling.h"
#include "qem/error.h"

namespace qem {

namespace {

using measure_detail::Surface;
using measure_detail::TriangleBvh;

using measure_detail::kQueryChunk;

struct Distances {
  double sum_d2 = 0, sum_d = 0, max_d = 0;
  std::size_t n = 0;  ///< points counted in the sums
};

/// Distances from `samples` (counted in the sums and the max) and `vertices` (max only) to `tree`.
/// Queries run in Morton order, warm-started from the previous answer within each fixed chunk; the
/// sums then run in sample order on one thread, so nothing depends on the thread count.
/// `sample_hits`, if given, receives the closest triangle of each sample (for the attribute error).
Distances distances(const TriangleBvh& tree, const std::vector<double>& samples,
                    const std::vector<double>& vertices, unsigned threads,
                    std::vector<std::uint32_t>* sample_hits = nullptr) {
  const std::size_t ns = samples.size() / 3;
  std::vector<double> points = samples;
  points.insert(points.end(), vertices.begin(), vertices.end());
  const std::vector<std::uint32_t> order = core::morton_order(points.size() / 3, [&](std::size_t i) {
    return Vec3(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
  });
  std::vector<double> d2(order.size());
  if (sample_hits) sample_hits->assign(ns, UINT32_MAX);
  core::for_chunks(order.size(), kQueryChunk, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    std::uint32_t hint = UINT32_MAX;  // reset per chunk: the warm start never crosses chunks
    for (std::size_t j = begin; j < end; ++j) {
      const std::uint32_t i = order[j];
      d2[i] = tree.closest(&points[3 * i], &hint).d2;
      if (sample_hits && i < ns) (*sample_hits)[i] = hint;  // the closest triangle, as closest() left it
    }
  });
  Distances total;
  for (std::size_t i = 0; i < d2.size(); ++i) {
    const double dist = std::sqrt(d2[i]);
    if (i < ns) total.sum_d2 += d2[i], total.sum_d += dist, ++total.n;
    total.max_d = std::max(total.max_d, dist);
  }
  return total;
}

}  // namespace

MeasureResult measure(MeshView original, MeshView approx, const MeasureOptions& options) {
  const Surface sn = measure_detail::make_surface(original, "original");
  const Surface si = measure_detail::make_surface(approx, "approximation");
  if (sn.triangle_count() == 0) throw Error("original: no face with non-zero area, nothing to measure");
  if (si.triangle_count() == 0) throw Error("approximation: no face with non-zero area, nothing to measure");
  const unsigned threads = core::resolve_threads(options.threads);
  if (options.samples + (sn.vertices.size() + si.vertices.size()) / 3 >= UINT32_MAX)
    throw Error("measure: " + std::to_string(options.samples) + " samples is too many (at most about 4e9)");

  // Same density on both surfaces: split the samples in proportion to the areas.
  const double total = double(options.samples);
  std::size_t nn = std::size_t(std::llround(total * sn.area / (sn.area + si.area)));
  std::size_t ni = options.samples > nn ? options.samples - nn : 0;
  nn = std::max<std::size_t>(nn, 1);
  ni = std::max<std::size_t>(ni, 1);

  // The two trees are independent: build the second on another thread when we have one.
  // The attribute error reuses the samples on the original and their closest triangles.
  const bool attributes = measure_detail::has_comparable_attributes(original, approx);
  std::vector<measure_detail::SamplePlace> places;
  TriangleBvh tree_n, tree_i;
  std::vector<double> xn, xi;
  core::side_by_side(
      threads,
      [&] {
        tree_i = TriangleBvh(si.corners);
        xi = measure_detail::sample_surface(si, ni, options.seed * 2 + 1);
      },
      [&] {
        tree_n = TriangleBvh(sn.corners);
        xn = measure_detail::sample_surface(sn, nn, options.seed * 2, attributes ? &places : nullptr);
      });
  static const std::vector<double> kNone;
  std::vector<std::uint32_t> hits;
  const Distances o2a = distances(tree_i, xn, options.include_vertices ? sn.vertices : kNone, threads,
                                  attributes ? &hits : nullptr);
  const Distances a2o = distances(tree_n, xi, options.include_vertices ? si.vertices : kNone, threads);

  MeasureResult r;
  r.bbox_diag = box_of_points(sn.vertices).diagonal();
  r.area_original = sn.area, r.area_approx = si.area;
  r.samples_original = nn, r.samples_approx = ni;
  r.degenerate_original = sn.degenerate, r.degenerate_approx = si.degenerate;
  const double n = double(o2a.n + a2o.n);
  r.E = (o2a.sum_d2 + a2o.sum_d2) / n;
  r.rms = std::sqrt(r.E);
  r.mean = (o2a.sum_d + a2o.sum_d) / n;
  r.h_original_to_approx = o2a.max_d;
  r.h_approx_to_original = a2o.max_d;
  r.hausdorff = std::max(o2a.max_d, a2o.max_d);
  r.mean_original_to_approx = o2a.sum_d / double(o2a.n);
  r.mean_approx_to_original = a2o.sum_d / double(a2o.n);
  r.rms_original_to_approx = std::sqrt(o2a.sum_d2 / double(o2a.n));
  r.rms_approx_to_original = std::sqrt(a2o.sum_d2 / double(a2o.n));
  const double diag = r.bbox_diag;
  r.E_rel = r.E / (diag * diag);
  r.rms_rel = r.rms / diag;
  r.mean_rel = r.mean / diag;
  r.hausdorff_rel = r.hausdorff / diag;

  if (attributes) {
    const measure_detail::AttributeErrors ae =
        measure_detail::attribute_errors(original, sn, approx, si, tree_i, xn, places, hits, threads);
    r.uv_rms = ae.uv_rms, r.normal_rms_deg = ae.normal_rms_deg, r.color_rms = ae.color_rms;
    r.attributes_by_material = ae.by_material;
  }
  // Cracks concern any mesh with seams, attributes or not: always counted (two sorts, cheap).
  r.cracks_in = measure_detail::welded_boundary_edges(original);
  r.cracks_out = measure_detail::welded_boundary_edges(approx);
  r.seam_cracks = r.cracks_out > r.cracks_in ? r.cracks_out - r.cracks_in : 0;

  if (options.per_vertex) {
    const std::size_t nv = approx.vertex_count();
    r.vertex_distance.assign(nv, 0.0);
    core::for_chunks(nv, kQueryChunk, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
      std::uint32_t hint = UINT32_MAX;  // mesh vertex order is usually coherent enough
      for (std::size_t v = begin; v < end; ++v)
        r.vertex_distance[v] = std::sqrt(tree_n.closest(&approx.positions[3 * v], &hint).d2);
    });
  }
  return r;
}

}  // namespace qem
