// The refit of an output with attributes, shared by simplify (src/simplify.cpp) and the
// partitioned run's final step (src/partition/simplify_partitioned.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "core/wedges.h"
#include "qem/simplify.h"
#include "refit/refit_points.h"

namespace qem {

// The refit of an output with attributes (wedges: the vertices of a seam share a position). It
// fits the surface welded by position, so that the wedges of one position move together and no
// crack opens; the positions that hold more than one wedge (UV seams, normal creases, colour and
// material boundaries, mirror lines) are held where the simplifier left them, on their seam with
// their values exactly on the chart's edge (moving them would pull one side's UVs out of its
// chart). The other vertices move with their values unchanged: moving the values along the
// gradients of their attribute quadrics measured the same to four digits (docs/attributes.md).
// `out.output_vertex_of_input`: each input vertex's output vertex (the refit's first guess of
// each point's closest face); `locked`: per output vertex (empty: none), held too;
// `closest_faces` as refit_to_points' (the welded mesh has the output's faces).
RefitResult refit_with_seams(const refit_detail::FitPoints& points, SimplifyResult& out, RefitOptions options,
                             const std::vector<std::uint8_t>& locked, const core::WedgeRefitData& data,
                             const core::SurfaceDistance* surface, std::vector<std::uint32_t>* closest_faces);

}  // namespace qem
