// Appearance attributes on wedges (Hoppe 1999, "New quadric metric for simplifying meshes with
// appearance attributes"). The working vertices are the input's distinct positions; a wedge is one
// set of attribute values at a position (the input's vertices that share it: split at UV seams,
// normal creases, colour and material boundaries). The link condition, borders and inversion see
// the welded surface; the wedges are what the attributes live on.
//
// Each wedge carries Hoppe's attribute quadric: for every face around it and every attribute
// channel, the area-weighted squared difference between the channel's value s and the face's
// linear fit g.p + d of that channel, 11 + 4m numbers for m channels. Minimised over s (each s at
// its optimum (G.p + D) / W), it is a plain quadric in p, added to the positional one: the
// placement then minimises both together (the reduced 3x3 solve of Hoppe & Marschner 2000).
#pragma once

#include <cstdint>
#include <vector>

#include "core/quadric.h"
#include "core/working_mesh.h"
#include "qem/simplify.h"

namespace qem::core {

/// Where one attribute's channels sit in a wedge's values, and how it is treated.
struct Channel {
  AttributeKind kind;
  std::uint32_t first, components;  // in the wedge's value row
  double weight;                    // 0: carried from the survivor, never interpolated
};

struct Wedges {
  std::vector<Channel> channels;
  std::uint32_t width = 0;            ///< values per wedge (all channels' components)
  std::uint32_t quadric_width = 0;    ///< 11 + 4 x interpolated components
  std::vector<std::uint32_t> vertex;  ///< working vertex of each wedge
  std::vector<std::uint32_t> next;    ///< the next wedge of the same vertex (a ring)
  std::vector<std::uint32_t> first;   ///< per working vertex, one of its wedges (kNoVertex: none)
  std::vector<std::uint32_t> source;  ///< input vertex of each wedge
  std::vector<std::uint32_t> merged_into;  ///< kNoVertex, or the wedge this one was merged into
  /// Live face corners that use each wedge. A wedge whose count falls to 0 leaves its vertex's ring
  /// (drop_unused): once the faces on one side of a seam are all gone, the seam is gone there too.
  std::vector<std::uint32_t> corners;
  std::vector<double> value;          ///< `width` per wedge, as given (the quadrics hold the weights)
  std::vector<double> quadric;        ///< `quadric_width` per wedge (see wedges.cpp)
  std::vector<std::uint32_t> material;  ///< the face material of each wedge (0 without materials)
  /// SeamMode::Permissive or Creases: a collapse may cross a seam (map_wedges), never a material
  /// boundary.
  bool permissive = false;
  /// SeamMode::Junctions: a junction (three or more wedges) may collapse onto another junction,
  /// crossing the seams there (map_wedges).
  bool junctions = false;
  /// Per working vertex (empty: none), SimplifyOptions::vertex_protect: its seams are never
  /// crossed, even when permissive.
  std::vector<std::uint8_t> protect;

  std::size_t count() const { return vertex.size(); }
  bool single(std::uint32_t v) const { return next[first[v]] == first[v]; }
  /// Three or more wedges at v: where UV charts, creases or colour regions meet.
  bool junction(std::uint32_t v) const {
    const std::uint32_t a = first[v], b = next[a];
    return b != a && next[b] != a;
  }
  /// The reduced quadric of wedge w (or of w and w2 merged, w2 != kNoVertex): its attribute error
  /// with every channel at its optimum, as a quadric in the position (weight 0: it adds error, not
  /// surface).
  Quadric reduced(std::uint32_t w, std::uint32_t w2) const;
  /// The same with any number of wedges merged into w.
  Quadric reduced(std::uint32_t w, const std::uint32_t* merged, std::size_t count) const;
  /// The attribute error of w with `merged` merged into it, at position p with w's values as they
  /// are (not at their optimum): what a collapse costs whose survivor keeps its values.
  double error_at(std::uint32_t w, const std::uint32_t* merged, std::size_t count, const Vec3& p) const;
  /// Sets w's interpolated channels to their optimum at p (after the merge).
  void update_values(std::uint32_t w, const Vec3& p);
  /// The same for a wedge whose vertex stays at p, texture coordinates excepted, over w and the
  /// other sides of a mirror line at it (wedges of the same input vertex and material), which take
  /// the same values.
  void refit_kept(std::uint32_t w, const Vec3& p);
  /// `removed` went into `survivor`, now at p: each removed wedge's quadric joins its partner's
  /// (map from map_wedges), and, if the survivor moved, its wedges take their optimal values at p,
  /// UVs within the box of the UVs of its neighbours on `faces` (the survivor's live faces, corners
  /// already mapped). A survivor that stays (a seam, a border, an endpoint placement) keeps its
  /// texture coordinates, as it keeps its position (a seam's UVs stay exactly on the chart's edge);
  /// its wedges that took a removed one's faces refit their other values (normals, colours) to
  /// their optimum at p, the value the collapse's cost was of; unless the collapse `crossed` a
  /// seam (permissive), whose cost was of the values kept.
  void merge(std::uint32_t survivor, std::uint32_t removed, bool moved, bool crossed, const Vec3& p,
             const std::vector<std::pair<std::uint32_t, std::uint32_t>>& map, const WorkingMesh& m,
             const std::vector<std::uint32_t>& faces);
  /// A face corner moved from wedge `from` to wedge `to` (`to` == kNoVertex: the face died).
  /// A wedge left with no corner is added to `emptied`, for drop_unused.
  void move_corner(std::uint32_t from, std::uint32_t to, std::vector<std::uint32_t>& emptied) {
    if (--corners[from] == 0) emptied.push_back(from);
    if (to != kNoVertex) ++corners[to];
  }
  /// Takes the wedges of `emptied` that still have no corner out of their vertex's ring (the last
  /// wedge of a vertex stays, so a ring is never empty), and clears `emptied`. A vertex left with
  /// one wedge is an ordinary vertex again: it may be removed and placed freely.
  void drop_unused(std::vector<std::uint32_t>& emptied);
  /// Forgetting (SimplifyOptions::forget): every wedge's quadric made again, as build_wedges makes
  /// it, from the live faces of `m` at their current positions and the wedges' current values.
  void renew_quadrics(const WorkingMesh& m);
  /// Renumbering (renumber.h): working vertex v is now vertex_to[v].
  void renumber(const std::vector<std::uint32_t>& vertex_to, std::size_t count);
  /// The surviving wedge an input vertex's values went into (kNoVertex: none).
  std::uint32_t final_wedge_of_input(std::uint32_t v) const;
  std::vector<std::uint32_t> of_input;  ///< the (first) wedge of each input vertex
};

/// What a crossing between two junctions costs (wedges.junctions, not permissive), in multiples of
/// the attribute error of its merged wedges. That error prices a corner that takes another chart's
/// texture coordinates as a smooth deviation of area x difference squared, while the texture drawn
/// on its faces now runs across the atlas. Measured on docs/benchmarks.md's attribute table
/// ("Seam junctions" there): at 1x and 3x the merges came early enough to raise beast.obj's UV
/// error at 1 % above meshoptimizer's; 10x is the lowest tried (10, 30) that kept every row's.
inline constexpr double kJunctionCrossingWeight = 10;

/// The wedges of `input` (one per referenced input vertex and face material) on the working
/// vertices `internal` (per input vertex), their attribute quadrics from the working faces, and the
/// wedge of every face corner (mesh.corner_wedge). Weights per kind from `options`.
Wedges build_wedges(MeshView input, const std::vector<std::uint32_t>& internal, WorkingMesh& mesh,
                    const SimplifyOptions& options);

/// The wedge map of collapsing `removed` into `survivor`: each of the removed vertex's wedges to the
/// survivor's wedge on the same side of the edge's faces. A wedge whose corners are all on the
/// edge's faces is vacated (it dies with them unless a removed wedge comes to it): a removed one
/// needs no partner, and a removed wedge that meets two of the survivor's goes to the one that is
/// not vacated (a crease that ends one face away goes with that face). Two removed wedges may go
/// into one on a manifold edge: their seam ends at the survivor and shortens along itself. False
/// if a living wedge of the removed vertex is on no face of the edge (the collapse would move a
/// seam or open it) or meets two living wedges of the survivor's (it would split one side).
/// `map` gets (removed wedge, survivor wedge) pairs.
/// Permissive (wedges.permissive, neither end protected): where those rules fail, each removed
/// wedge goes to the survivor's wedge it meets on an edge face, else to the survivor's wedge of the
/// same material nearest in weighted attribute values, and `crossed` (if given) is set; still
/// false if a material would merge into another. The same crossing between two junctions
/// (wedges.junctions, both ends Wedges::junction, neither protected) when not permissive.
bool map_wedges(const WorkingMesh& mesh, const Wedges& wedges, std::uint32_t survivor, std::uint32_t removed,
                std::vector<std::pair<std::uint32_t, std::uint32_t>>& map, bool* crossed = nullptr);

/// SimplifyOptions::lock_seams: every working vertex with more than one wedge (a UV seam, a normal
/// crease, a colour or material boundary, a mirror line) is locked (WorkingMesh::locked).
void lock_seam_vertices(const Wedges& wedges, WorkingMesh& mesh);

/// What the refit after a run needs to know of each output vertex (simplify.cpp).
struct WedgeRefitData {
  /// Whether its position holds more than one wedge in use (a seam, crease, material boundary or
  /// mirror line, even where the output merged a mirror line's two sides back into one vertex).
  std::vector<std::uint8_t> on_seam;
};

/// The output with attributes: one vertex per surviving wedge, in input order, with the input's
/// attributes (output_values) and face materials; provenance as build_output's, and, when asked,
/// each input vertex's output vertex and the refit's data.
Mesh build_wedge_output(const WorkingMesh& mesh, const Wedges& wedges, MeshView input, std::vector<std::uint32_t>& vertex_source,
                        std::vector<std::uint32_t>& face_source, std::vector<std::uint32_t>* output_vertex_of_input,
                        WedgeRefitData* refit = nullptr);

/// The output's attribute values of wedge w: unweighted, normals unit, colours in [0, 1], skin
/// weights summing to 1.
void output_values(const Wedges& wedges, std::uint32_t w, double* out);

}  // namespace qem::core
