// Two-sided sheets (SimplifyOptions::two_sided). An input that makes a sheet two-sided by a
// reversed copy of each face (a face and its twin on the same three points, turning opposite
// ways) closes the sheet's rim: welded by position, every edge there has the face and its twin, so
// nothing is open. The core keeps one face of each such pair (both would count their plane twice
// and block every collapse as non-manifold, core/working_mesh.cpp), which leaves the rim open and
// the back side gone. These put twins back after the run: on the output faces along a border whose
// input face had one (TwoSided::Rims: the rim is closed again as it was in the input; inside the
// sheet the back is left to a two-sided material), or on every output face whose input face had
// one (TwoSided::All: both sides, for renderers that cull back faces).
#pragma once

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "qem/simplify.h"

namespace qem {

/// An input face that had a reversed twin, and the twin (input face ids).
using TwinFaces = std::pair<std::uint32_t, std::uint32_t>;

/// The faces of `mesh` with an edge that no other face has, welded by position, whose input face
/// (`face_source`) had a reversed twin (`twins`, in increasing order of the first), in increasing
/// order.
std::vector<std::uint32_t> faces_on_twinned_rims(const Mesh& mesh, std::span<const std::uint32_t> face_source,
                                                 std::span<const TwinFaces> twins, unsigned threads);

/// The faces of `mesh` whose input face (`face_source`) had a reversed twin, in increasing order.
std::vector<std::uint32_t> faces_with_twins(std::span<const std::uint32_t> face_source,
                                            std::span<const TwinFaces> twins);

/// The vertices add_reversed_twins adds for `faces`: with a normal (or tangent) attribute, one per
/// distinct corner (the back side's normal turns the other way); without, none (the twins share
/// the front's vertices).
std::size_t twin_vertices_needed(const Mesh& mesh, std::span<const std::uint32_t> faces);

/// Appends each face's twin (its corners in the opposite turn, same material; its face_source the
/// input twin of the face's) to `result`'s mesh, with the vertices twin_vertices_needed says (same
/// position and values, normals negated, a tangent's handedness too, the same vertex_source).
void add_reversed_twins(SimplifyResult& result, std::span<const std::uint32_t> faces, std::span<const TwinFaces> twins);

}  // namespace qem
