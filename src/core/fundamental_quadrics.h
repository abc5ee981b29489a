// The quadrics every vertex starts with: the fundamental error quadrics of its faces' planes
// (GH97 §5), weighted (HG99 §2), plus the constraint planes of its border edges (GH97 §6).
#pragma once

#include <vector>

#include "core/quadric.h"
#include "core/settings.h"
#include "core/valid_pairs.h"
#include "core/working_mesh.h"
#include "qem/simplify.h"

namespace qem::core {

/// Per vertex, the sum of the plane quadrics K_p of its faces, weighted by area (HG99 §2: the
/// quadric integrates squared distance over the surface), uniformly (GH97 §5) or by corner angle.
/// Zero-area faces have no plane and add nothing. Reads the live faces (mesh.face_alive), each
/// vertex's sum in face order.
/// Written into `quadrics` (resized to the vertices; every entry overwritten), so that a renewal
/// (core/forgetting.h) reuses the array it replaces instead of fresh, zeroed memory.
void face_quadrics(const WorkingMesh& mesh, Weighting weighting, unsigned threads, std::vector<Quadric>& quadrics);

/// GH97 §6: marks the ends of every border edge (`edges`: unique_edges, with face counts) and, when
/// `weight` > 0, adds to both ends the plane through the edge perpendicular to its face, weighted
/// by weight x edge length² under area weighting (so it keeps its proportion to the faces' quadrics
/// at every resolution and scale), else by weight.
void add_boundary_planes(WorkingMesh& mesh, const std::vector<Edge>& edges, double weight, Weighting weighting,
                         std::vector<Quadric>& quadrics);

/// The constraint planes a run adds to the face quadrics, at the start and at each renewal
/// (forgetting.h): the border planes (add_boundary_planes, which also marks the border) and, when
/// the run carries wedges (`seams`), the seam planes (seam_planes.h), with the settings' weights.
void add_constraint_planes(WorkingMesh& mesh, const std::vector<Edge>& edges, const Settings& settings, bool seams,
                           std::vector<Quadric>& quadrics);

}  // namespace qem::core
