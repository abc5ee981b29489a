#include "quantized_borders.h"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "core/same_position.h"
#include "core/valid_pairs.h"

namespace qem {
namespace {

using Point = std::array<double, 3>;

Point position(const Mesh& m, std::size_t v) {
  const double* p = &m.positions[3 * v];
  return {p[0], p[1], p[2]};
}

/// Whether each vertex of `m` lies on a border: an edge of one face, the mesh welded by position
/// (its seams, vertices split at one position, are not borders).
std::vector<std::uint8_t> border_vertices(const Mesh& m) {
  const std::vector<std::uint32_t> first = core::first_at_same_position(MeshView(m), 1);
  std::vector<std::uint32_t> welded(m.indices.size());
  for (std::size_t i = 0; i < welded.size(); ++i) welded[i] = first[m.indices[i]];
  const std::vector<std::uint8_t> on = core::border_vertices(welded, m.vertex_count(), 1);
  std::vector<std::uint8_t> border(m.vertex_count());
  for (std::size_t v = 0; v < border.size(); ++v) border[v] = on[first[v]];
  return border;
}

}  // namespace

std::size_t snap_quantized_borders(std::span<Mesh> parts, std::span<const double> steps) {
  double largest = 0, size = 0;
  for (double s : steps)
    if (std::isfinite(s)) largest = std::max(largest, s);
  if (largest <= 0) return 0;
  for (const Mesh& m : parts)
    for (double x : m.positions) size = std::max(size, std::abs(x));
  // No two parts' tolerance (below) exceeds a cell, so a match is in a neighbouring one.
  const double cell = 1.01 * largest + 4 * FLT_EPSILON * size;
  struct Entry {
    Point p;
    double step;
  };
  std::map<Point, std::vector<Entry>> grid;  // earlier parts' border vertices by cell
  const auto cell_of = [&](const Point& p) {
    return Point{std::floor(p[0] / cell), std::floor(p[1] / cell), std::floor(p[2] / cell)};
  };
  std::size_t moved = 0;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    Mesh& m = parts[k];
    const double own = std::isfinite(steps[k]) ? steps[k] : 0;
    const std::vector<std::uint8_t> border = border_vertices(m);
    std::vector<Point> snapped(m.vertex_count());
    std::vector<std::uint8_t> moves(m.vertex_count(), 0);
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
      if (!border[v] || grid.empty()) continue;
      const Point p = position(m, v), c = cell_of(p);
      double best = INFINITY;
      for (double dx : {-1.0, 0.0, 1.0})
        for (double dy : {-1.0, 0.0, 1.0})
          for (double dz : {-1.0, 0.0, 1.0}) {
            const auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
            if (it == grid.end()) continue;
            for (const Entry& e : it->second) {
              if (e.step + own <= 0) continue;  // two unquantized parts: matched exactly, not here
              double d = 0;
              for (int a = 0; a < 3; ++a) d = std::max(d, std::abs(p[a] - e.p[a]));
              // half of each grid's step, and the rounding of the dequantized floats
              const double within = 0.5 * (e.step + own) * 1.01 + 4 * FLT_EPSILON * size;
              if (d <= within && d < best) best = d, snapped[v] = e.p;
            }
          }
      moves[v] = best < INFINITY && best > 0;
    }
    for (std::size_t v = 0; v < m.vertex_count(); ++v)
      if (moves[v]) std::copy(snapped[v].begin(), snapped[v].end(), &m.positions[3 * v]), ++moved;
    for (std::size_t v = 0; v < m.vertex_count(); ++v)
      if (border[v]) grid[cell_of(position(m, v))].push_back({position(m, v), own});
  }
  return moved;
}

void snap_quantized_primitives(std::span<Mesh> meshes, std::span<const std::size_t> primitives,
                               const std::vector<GltfPrimitiveInfo>& info) {
  std::map<std::size_t, std::vector<std::size_t>> by_placement;  // (in document order)
  for (std::size_t k = 0; k < primitives.size(); ++k)
    by_placement[info[primitives[k]].placement].push_back(k);
  for (const auto& [placement, members] : by_placement) {
    std::vector<double> steps;
    for (std::size_t k : members) steps.push_back(info[primitives[k]].position_step);
    if (members.size() < 2 || *std::max_element(steps.begin(), steps.end()) <= 0) continue;
    std::vector<Mesh> parts;
    for (std::size_t k : members) parts.push_back(std::move(meshes[k]));
    snap_quantized_borders(parts, steps);
    for (std::size_t i = 0; i < members.size(); ++i) meshes[members[i]] = std::move(parts[i]);
  }
}

}  // namespace qem
