// Topological and geometric facts about a mesh: what `qem info` prints, and what tests check.
//
// The definitions follow the reference statistics of the shared test-mesh catalogue, so numbers can
// be compared one to one:
//  - an edge is an unordered vertex pair of a face whose three indices differ (faces with a repeated
//    index contribute no edges);
//  - a vertex is non-manifold when the faces around it form more than one fan, two faces being in
//    the same fan when they share an edge that has exactly two faces;
//  - components join faces through shared vertices (every face, degenerate or not);
//  - a boundary loop is a connected component of the graph of boundary edges.
#pragma once

#include <cstddef>

#include "qem/mesh.h"

namespace qem {

struct MeshInfo {
  std::size_t vertices = 0, faces = 0;
  std::size_t unreferenced_vertices = 0;
  std::size_t edges = 0;
  std::size_t boundary_edges = 0, boundary_loops = 0;
  std::size_t non_manifold_edges = 0;     ///< edges with more than two incident faces
  std::size_t non_manifold_vertices = 0;  ///< vertices whose faces form more than one fan
  std::size_t components = 0;             ///< face-connected components (via shared vertices)
  std::size_t duplicate_faces = 0;        ///< faces with the same vertex set as an earlier face
  std::size_t degenerate_faces = 0;       ///< repeated index or zero area
  std::size_t zero_area_faces = 0;        ///< the degenerate faces with three distinct indices
  std::size_t orientation_conflicts = 0;  ///< manifold edges whose two faces traverse it the same way
  /// Euler characteristic V - E + F over referenced vertices and faces without repeated indices.
  long long euler = 0;
  /// Sum of the genera of the components when the mesh is a closed, consistently oriented
  /// 2-manifold without repeated-index faces (from chi = 2c - 2g); -1 otherwise.
  long long genus = -1;
  Box box;
  /// Positions held by more than one vertex (bit-identical coordinates): the seams of a wedge mesh
  /// (UV seams, normal creases, OBJ corners with different vt/vn), or an unwelded mesh.
  std::size_t seam_vertices = 0;
  /// Distinct material indices used by the faces (0 when the mesh has no face materials).
  std::size_t materials = 0;

  /// No boundary edges and no non-manifold edges.
  bool watertight() const { return boundary_edges == 0 && non_manifold_edges == 0; }
  /// No non-manifold edges or vertices.
  bool manifold() const { return non_manifold_edges == 0 && non_manifold_vertices == 0; }
};

/// Computes the facts in O(V + F) time and memory (a bucket sort of the half-edges by their
/// smaller vertex, no hashing). Throws qem::Error when an index is out of range or a coordinate is
/// not finite.
MeshInfo mesh_info(MeshView mesh);

}  // namespace qem
