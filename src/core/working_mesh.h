// The mesh the simplifier works on: the input's referenced vertices in a normalised frame,
// renumbered along a Morton curve, and its faces without degenerate or duplicate ones, plus the
// per-vertex flags the contraction rules read. Every tolerance is relative to this frame, so the
// result does not depend on the model's position or scale.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/border_chains.h"
#include "core/packed_normal.h"
#include "core/quadric.h"
#include "core/vertex_lists.h"
#include "geometry/frame.h"
#include "qem/mesh.h"

namespace qem::core {

/// "No vertex": a removed vertex in a renumbering, an input vertex that left the mesh.
inline constexpr std::uint32_t kNoVertex = 0xffffffffu;

struct WorkingMesh {
  Frame frame;  ///< of the referenced vertices: p_work = (p_in - center) * (1 / scale)

  std::vector<Vec3> pos;
  std::vector<std::uint32_t> tri;            ///< 3 per working face
  std::vector<std::uint32_t> corner_wedge;   ///< with attributes, 3 per working face (wedges.h)
  std::vector<std::uint8_t> face_alive;
  std::vector<std::uint32_t> face_source;    ///< input face of each working face
  /// The normal of each working face's input face (collapse_checks.h: no face may come to face
  /// away from it).
  std::vector<PackedNormal> input_normal;
  std::vector<std::uint32_t> source_vertex;  ///< input vertex of each working vertex
  std::vector<std::uint8_t> moved;           ///< left its input position (else written back exactly)
  std::vector<std::uint8_t> boundary;        ///< on a border edge (GH97 §6), inherited through merges
  /// Under exact borders, kHardCorner or kSoftCorner (border_placement.h); empty otherwise.
  std::vector<std::uint8_t> corner;
  /// Under exact borders: the input's border polylines, and where on them each vertex lies
  /// (border_chains.h; a vertex off the borders has none); empty otherwise.
  BorderChains chains;
  std::vector<BorderSpot> border_spot;
  /// Set on both ends of a contracted threshold pair and inherited through merges: an aggregation
  /// joint, non-manifold by design (GH97 §3.2), where the link condition does not apply.
  std::vector<std::uint8_t> aggregated;
  std::vector<std::uint8_t> locked;  ///< SimplifyOptions::vertex_lock per working vertex (empty: none)
  VertexLists vertex_faces;  ///< each vertex's faces (exact in the greedy order; see order_passes)

  std::size_t faces_alive = 0, vertices_alive = 0;
  std::size_t dropped_degenerate = 0, dropped_duplicate = 0;  ///< input faces left out
  /// Each input face kept that had a duplicate of the opposite orientation dropped (a two-sided
  /// sheet's faces, a flap), with the first such duplicate, in increasing order of the kept face:
  /// qem/simplify.h, SimplifyOptions::two_sided.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> reversed_twins;

  std::size_t vertex_count() const { return pos.size(); }
  const std::uint32_t* face(std::uint32_t f) const { return &tri[3 * std::size_t(f)]; }
  bool face_has(std::uint32_t f, std::uint32_t v) const {
    const std::uint32_t* t = face(f);
    return t[0] == v || t[1] == v || t[2] == v;
  }
  /// The (unnormalised) normal of face t with vertex `moved_vertex` put at `to`.
  Vec3 face_normal(const std::uint32_t* t, std::uint32_t moved_vertex, const Vec3& to) const {
    const Vec3& p0 = t[0] == moved_vertex ? to : pos[t[0]];
    const Vec3& p1 = t[1] == moved_vertex ? to : pos[t[1]];
    const Vec3& p2 = t[2] == moved_vertex ? to : pos[t[2]];
    return cross(p1 - p0, p2 - p0);
  }
  /// Whether v may not move: locked, or on a border under --lock-border.
  bool held(std::uint32_t v, bool lock_border) const {
    return (lock_border && boundary[v]) || (!locked.empty() && locked[v]);
  }
  /// A vertex's position in the input's frame: its exact input coordinates if it never moved.
  Vec3 output_position(std::uint32_t v, MeshView input) const {
    if (moved[v]) return frame.to_model(pos[v]);
    const double* p = &input.positions[3 * std::size_t(source_vertex[v])];
    return {p[0], p[1], p[2]};
  }
  /// Each vertex's live faces, in face order.
  void rebuild_face_lists();
  /// Renumbering (see renumber.h): vertex v becomes vertex_to[v] (kNoVertex: gone), faces keep
  /// their order and the dead ones go. The face lists must be rebuilt after it.
  void squeeze_faces(const std::vector<std::uint32_t>& vertex_to);
  void squeeze_vertices(const std::vector<std::uint32_t>& vertex_to, std::size_t count);
};

/// Renumbering helper: a[vertex_to[i]] = a[i] for every kept i (vertex_to never moves one up),
/// then a is cut to `count`.
template <class Array>
void squeeze_by(const std::vector<std::uint32_t>& vertex_to, std::size_t count, Array& a) {
  for (std::size_t i = 0; i < vertex_to.size(); ++i)
    if (vertex_to[i] != kNoVertex) a[vertex_to[i]] = a[i];
  a.resize(count);
}

/// Checks the input (check_mesh), keeps its referenced vertices and its faces that are neither
/// degenerate nor duplicates (kept once, the first in input order), and normalises the frame.
/// With attributes, the working vertices are the input's distinct positions, and `internal` (if
/// given) gets each input vertex's working vertex.
WorkingMesh prepare_input(MeshView input, std::vector<std::uint32_t>* internal = nullptr);

/// The output: surviving vertices and faces in input order. Fills, when not null, each output
/// vertex's and face's input index, and the new index of each working vertex (kNoVertex: dropped).
Mesh build_output(const WorkingMesh& mesh, MeshView input, std::vector<std::uint32_t>* vertex_source,
                  std::vector<std::uint32_t>* face_source, std::vector<std::uint32_t>* output_index);

}  // namespace qem::core
