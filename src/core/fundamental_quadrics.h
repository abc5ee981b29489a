// The quadrics every vertex starts with: the fundamental error quadrics of its faces' planes
// (GH97 §5), weighted (HG99 §2), plus the constraint planes of its border edges (GH97 §6).
#pragma once

#include <span>
#include <vector>

#include "core/quadric.h"
#include "core/valid_pairs.h"
#include "core/working_mesh.h"
#include "qem/simplify.h"

namespace qem::core {

/// Per vertex, the sum of the plane quadrics K_p of its faces, weighted by area (HG99 §2: the
/// quadric integrates squared distance over the surface), uniformly (GH97 §5) or by corner angle.
/// Zero-area faces have no plane and add nothing.
std::vector<Quadric> face_quadrics(const WorkingMesh& mesh, Weighting weighting);

/// Quadrics a caller carries into the run in place of face_quadrics (Garland & Shaffer 2002 §3: the
/// quadric each cluster accumulated from the faces of the original surface becomes the initial
/// quadric of its vertex). One per input vertex, area-weighted (HG99 §2), in the input's units and
/// evaluated at p - origin (an origin near the model keeps the constant term small).
struct CarriedQuadrics {
  std::span<const Quadric> per_vertex;
  Vec3 origin;
};

/// The carried quadric of each working vertex (mesh.source_vertex), taken into the working frame
/// as face_quadrics would have computed it there: positions (p - center) / scale, so areas
/// (weights) shrink by scale^2 and squared distances by scale^2.
std::vector<Quadric> carried_quadrics(const WorkingMesh& mesh, const CarriedQuadrics& carried);

/// GH97 §6: marks the ends of every border edge (`edges`: unique_edges, with face counts) and, when
/// `weight` > 0, adds to both ends the plane through the edge perpendicular to its face, weighted
/// by weight x edge length² under area weighting (so it keeps its proportion to the faces' quadrics
/// at every resolution and scale), else by weight.
void add_boundary_planes(WorkingMesh& mesh, const std::vector<Edge>& edges, double weight, Weighting weighting,
                         std::vector<Quadric>& quadrics);

}  // namespace qem::core
