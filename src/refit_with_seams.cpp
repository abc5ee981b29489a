#include "refit_with_seams.h"

#include <algorithm>
#include <array>

namespace qem {

RefitResult refit_with_seams(const refit_detail::FitPoints& points, SimplifyResult& out, RefitOptions options,
                             const std::vector<std::uint8_t>& locked, const core::WedgeRefitData& data,
                             const core::SurfaceDistance* surface,
                             std::vector<std::uint32_t>* closest_faces) {
  Mesh& mesh = out.mesh;
  const std::size_t n = mesh.vertex_count();
  std::vector<std::uint32_t> order(n);
  for (std::uint32_t v = 0; v < n; ++v) order[v] = v;
  const auto at = [&](std::uint32_t v) {
    return std::array<double, 3>{mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]};
  };
  std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return at(x) != at(y) ? at(x) < at(y) : x < y; });
  // Welded vertices numbered in order of their first output vertex, so the result does not hang
  // on the sort's order of equal keys.
  std::vector<std::uint32_t> group(n), welded_of(n, UINT32_MAX);
  for (std::size_t i = 0; i < n; ++i) group[order[i]] = i > 0 && at(order[i]) == at(order[i - 1]) ? group[order[i - 1]] : order[i];
  Mesh welded;
  std::vector<std::uint32_t> wedges_at;  // output vertices per welded vertex
  std::vector<std::uint8_t> fixed;
  for (std::uint32_t v = 0; v < n; ++v) {
    std::uint32_t& w = welded_of[group[v]];
    if (w == UINT32_MAX) {
      w = std::uint32_t(wedges_at.size());
      wedges_at.push_back(0), fixed.push_back(0);
      welded.positions.insert(welded.positions.end(), &mesh.positions[3 * v], &mesh.positions[3 * v] + 3);
    }
    welded_of[v] = w;
    ++wedges_at[w];
    if ((!locked.empty() && locked[v]) || data.on_seam[v]) fixed[w] = 1;
  }
  for (std::size_t w = 0; w < fixed.size(); ++w) fixed[w] |= wedges_at[w] > 1;
  welded.indices.reserve(mesh.indices.size());
  for (std::uint32_t v : mesh.indices) welded.indices.push_back(welded_of[v]);
  std::vector<std::uint32_t> near = out.output_vertex_of_input;
  for (std::uint32_t& v : near)
    if (v != SimplifyResult::kUnmapped) v = welded_of[v];
  options.fixed_vertices = fixed;
  const RefitResult fit =
      refit_detail::refit_to_points(points, welded, options, near, surface, closest_faces);
  for (std::uint32_t v = 0; v < n; ++v)
    std::copy_n(&welded.positions[3 * std::size_t(welded_of[v])], 3, &mesh.positions[3 * std::size_t(v)]);
  return fit;
}

}  // namespace qem
