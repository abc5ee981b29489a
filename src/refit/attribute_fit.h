// The attribute fit after a simplification with attributes: the output's positions and faces
// fixed, every output vertex off the seams takes the attribute values that best fit the input's
// attributes over its surface, in the least-squares sense, at the points of the output closest to
// points of the input's faces (Hoppe 1996, "Progressive meshes" §4.2, fits scalar attributes the
// same way, by projecting points of the original onto the approximation). The wedge quadrics'
// optimum (Hoppe 1999) fits each value when its collapse is made, to the faces then merged into
// its wedge; this fit sees the final faces and positions, as a closest-point measure does.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "qem/mesh.h"
#include "qem/simplify.h"

namespace qem::refit_detail {

/// Whether fit_attributes has anything to fit: an attribute of a kind that is interpolated
/// (normals, texture coordinates, colours, scalars) with a weight above 0 in `weights`.
bool has_fitted_attributes(std::span<const VertexAttribute> attributes, const AttributeWeights& weights);

/// Fits the attributes of `out` (the simplified mesh, its attributes in the order of the input's
/// `attributes`) to the input's (`positions`, `indices`, `attributes`): points of each input face
/// (its centroid, or four points when the output has more than a quarter of the input's faces),
/// weighted by their share of its area, are projected onto the nearest of the output faces around
/// the output vertices its corners went into (`output_vertex_of_input`: their wedges, so on the
/// face's side of every seam), and the attributes interpolated there are fitted to the input's.
/// `held` (per output vertex, 1: keeps its values): the seam vertices, whose values stay those of
/// the input's vertex on the chart's edge, as their positions stay on the seam, so both sides of a
/// seam keep matching values. Normals come out unit, colours in [0, 1], texture coordinates within
/// the box of their neighbours' (as the placement's).
void fit_attributes(std::span<const double> positions, std::span<const std::uint32_t> indices,
                    std::span<const VertexAttribute> attributes, const AttributeWeights& weights,
                    std::span<const std::uint32_t> output_vertex_of_input, std::span<const std::uint8_t> held,
                    Mesh& out);

}  // namespace qem::refit_detail
