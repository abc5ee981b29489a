// Constraint planes along attribute seams (GH97 §6's boundary planes, applied to the edges where
// the wedges change: UV seams, normal creases, material boundaries). A seam's vertices never leave
// it (wedge_placement.cpp), but a collapse along the seam can still bend the seam's line within
// the surface; these planes, perpendicular to each face through the seam edge, charge for that.
// Without them nothing in the positional quadric sees a tangential move of the seam line, and the
// texture charts that meet there shift against each other.
#pragma once

#include <cstdint>
#include <vector>

#include "core/quadric.h"
#include "core/valid_pairs.h"
#include "core/working_mesh.h"
#include "qem/simplify.h"

namespace qem::core {

/// Adds, for every interior edge whose two faces give an end different wedges, one plane per face
/// through the edge and perpendicular to the face, weighted by `weight` x the squared edge length
/// (area weighting; `weight` alone otherwise) and of zero surface weight, to both ends' quadrics.
void add_seam_planes(const WorkingMesh& m, const std::vector<Edge>& edges, double weight, Weighting weighting,
                     std::vector<Quadric>& quadric);

}  // namespace qem::core
