// The refit that follows a simplification (SimplifyOptions::refit_rounds), outside the core: it
// takes the core's output and its map of where each input vertex went.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/distance_bound.h"
#include "core/far_repair.h"
#include "qem/mesh.h"
#include "qem/progressive.h"
#include "qem/refit.h"
#include "qem/simplify.h"
#include "refit/refit_points.h"

namespace qem {

/// The refit options `simplify` uses for `options`: the same rounds, points per vertex, face turn
/// limit and threads; the border locked with lock_border or exact_border (a border vertex the
/// refit slid along a curved border would leave the input's polyline); an absolute max_distance
/// (simplify resolves a relative one). `qem lod` refits each level with them, as `simplify` would.
RefitOptions refit_options_for(const SimplifyOptions& options);

/// The same for a run whose output has `output_vertices` vertices for `input_vertices` referenced
/// input vertices: with SimplifyOptions::refit_by_reduction the rounds (0: no refit) and points
/// per vertex follow the reduction.
RefitOptions refit_options_for(const SimplifyOptions& options, std::size_t input_vertices,
                               std::size_t output_vertices);

/// Refits the levels of a chain (`qem lod`, Python's lod) each as `simplify` would refit a run to
/// that level: the levels that get the same refit are refitted together.
void refit_levels(MeshView original, std::span<ReplayLevel> levels, const SimplifyOptions& options,
                  std::size_t input_vertices);

/// Per output vertex (`vertices` of them): on a seam (`on_seam`, from the core's wedge data) or
/// locked (`fixed`): what the refit's followers, the far-place repair and the attribute fit,
/// leave as it is. Either span may be shorter (empty: none).
std::vector<std::uint8_t> seam_or_locked(std::span<const std::uint8_t> on_seam, std::span<const std::uint8_t> fixed,
                                         std::size_t vertices);

/// The far-place repair of `mesh` with `options`' turn limit and threads (core/far_repair.h),
/// against the input (`input`'s positions) as `points` and `surface`; `on_border` per point (1:
/// on the input's border; empty: found by the repair when it needs them, unless the mesh has vertex
/// properties; all zero: no relocation at a border); `closest_faces` per point (empty: none) as
/// FarRepairOptions::point_faces. A relocated vertex that stands at an input vertex takes its exact
/// coordinates.
core::FarRepairResult repair_mesh(Mesh& mesh, const SimplifyOptions& options, MeshView input,
                                  std::span<const std::uint8_t> on_border,
                                  const refit_detail::FitPoints& points, const core::SurfaceDistance& surface,
                                  std::span<const std::uint8_t> held,
                                  std::span<const std::uint32_t> closest_faces);

/// The far-place repair (core/far_repair.h) of `result` after its refit, against the input (its
/// positions and the faces the run used) as points and surface (those of the refit), `held`
/// vertices left as they are; with the input's attributes (in `input`) no flip or move raises
/// the error of appearance. Counts it in `result` and carries its provenance across relocations.
/// `closest_faces`: per point, its closest face of `result.mesh` as the refit left it
/// (refit_to_points'), where the repair's search for it starts; empty: none.
void repair_after_refit(SimplifyResult& result, const SimplifyOptions& options, MeshView input,
                        const refit_detail::FitPoints& points, const core::SurfaceDistance& surface,
                        std::span<const std::uint8_t> held, std::span<const std::uint32_t> closest_faces);

}  // namespace qem
