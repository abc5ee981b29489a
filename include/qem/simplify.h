// Surface simplification by iterative pair contraction with quadric error metrics
// (Garland & Heckbert 1997, "GH97"; area weighting from Heckbert & Garland 1999, "HG99").
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "qem/mesh.h"

namespace qem {

/// How face planes are weighted when vertex quadrics are accumulated.
enum class Weighting {
  Area,     ///< by triangle area (HG99 §2): the quadric integrates squared distance over the surface
  Uniform,  ///< every plane counts once (GH97 §5)
  Angle,    ///< by the triangle's corner angle at the vertex
};

/// Where a contracted pair's new vertex goes (GH97 §4).
enum class Placement {
  Optimal,    ///< minimise the quadric (3x3 solve); fall back to Segment, then Endpoints+midpoint
  Segment,    ///< the best point on the segment v1-v2
  Midpoint,   ///< always the midpoint
  Endpoints,  ///< the better endpoint or the midpoint ("fixed placement" of GH97 Fig. 6)
};

/// The order in which contractions are made.
enum class Scheme {
  /// Strictly cheapest first, one at a time, from an updatable heap: exactly GH97 §4.
  Greedy,
  /// In passes (the scheme of meshoptimizer): rank every candidate, sort them, and contract the
  /// cheap ones in order, each vertex at most once a pass; then re-rank. Far fewer cache misses.
  Passes,
};

/// What happens to a contraction that would flip a neighbouring face (GH97 §6).
enum class InversionPolicy { Forbid, Penalize, Ignore };

/// What becomes of the reversed copies that make a sheet two-sided (SimplifyOptions::two_sided).
enum class TwoSided {
  Rims,  ///< the twins of the output faces along a rim come back: the rim stays closed, as in the input
  All,   ///< every output face whose input face had a twin gets it back: both sides stay, culled or not
  None,  ///< every twin stays out: one side
};

/// With attributes, what a collapse may do at a seam (UV seam, normal crease, colour or material
/// boundary, mirror line: a position with more than one attribute set; SimplifyOptions::seams,
/// docs/attributes.md). No mode crosses a material boundary or opens a crack (positions stay shared).
enum class SeamMode {
  /// As Strict, except that a junction (a vertex where three or more wedges meet: UV charts,
  /// creases or colour regions meeting at a point) may collapse along an edge onto another
  /// junction, its wedges that meet none of the survivor's on the edge's faces merging into the
  /// survivor's wedge of the same material nearest in value, when the cost, which then includes
  /// ten times the attribute error of those merges, allows (meshoptimizer's default for its
  /// "complex" vertices). Junctions that never merge block targets on meshes with many charts or
  /// creases; the error term keeps a merge to where its attributes differ little ("Seam junctions").
  Junctions,
  /// A collapse runs only along a seam, both sides together, and a junction never moves.
  Strict,
  /// As Permissive, but UV seams are never crossed (every vertex where texture coordinates jump is
  /// protected, as by vertex_protect): only normal creases and colour boundaries are, when the
  /// error allows (gltfpack's `-sp`); crossing a crease smooths its shading.
  Creases,
  /// A collapse may cross a UV seam, normal crease or colour boundary (never at a protected
  /// vertex) when its cost, which then includes the attribute error of merging the two sides,
  /// allows (meshoptimizer's SimplifyPermissive). Reaches targets that strict seams block (many
  /// small UV charts), at the price of attribute quality along the seams it crosses: joining two
  /// charts' coordinates on the faces round it can smear the texture or lose a small feature drawn
  /// in its own chart ("Permissive seams").
  Permissive,
};

/// Why simplification stopped.
enum class StopReason {
  TargetReached,    ///< a face / vertex count target was met
  ErrorLimit,       ///< every remaining contraction exceeds max_error
  NoValidPair,      ///< no contraction is allowed (locked borders, topology, inversion) before the target
  AlreadyBelowTarget,
  Cancelled,
};
const char* to_string(StopReason reason);
const char* to_string(Weighting w);
const char* to_string(Placement p);
const char* to_string(Scheme s);
// The names above and below come from one table per enum (src/option_names.cpp).
const char* to_string(InversionPolicy policy);
const char* to_string(TwoSided t);
const char* to_string(SeamMode s);
/// The value called `name` (a to_string name, which is also the command line's: "area", "off"):
/// true and `out` set, or false and `out` unchanged if no value has that name.
bool from_string(const std::string& name, Weighting& out);
bool from_string(const std::string& name, Placement& out);
bool from_string(const std::string& name, Scheme& out);
bool from_string(const std::string& name, InversionPolicy& out);
bool from_string(const std::string& name, TwoSided& out);
bool from_string(const std::string& name, SeamMode& out);
/// The names of all values of an option enum (Weighting, Placement, Scheme, InversionPolicy,
/// TwoSided, SeamMode; no other is defined), in declaration order: the choices a front end offers.
template <class Enum>
std::vector<std::string> option_names();

/// The whole contraction sequence of one run (GH97 §3: M_n, M_n-1, ..., M_g), in input vertex and
/// face indices, so that any intermediate mesh can be rebuilt (see qem/progressive.h).
struct ContractionLog {
  /// Input faces the run started from (degenerate and duplicate input faces are not among them).
  std::vector<std::uint32_t> initial_faces;
  // One entry per contraction, in order:
  std::vector<std::uint32_t> kept;     ///< input vertex that survives
  std::vector<std::uint32_t> removed;  ///< input vertex merged into `kept`
  std::vector<double> position;        ///< 3 per contraction: where `kept` went (output coordinates)
  std::vector<double> error;           ///< contraction error, distance units
  /// Input faces that died in contraction i: dead_faces[dead_begin[i] .. dead_begin[i+1]).
  std::vector<std::uint32_t> dead_begin{0};
  std::vector<std::uint32_t> dead_faces;

  std::size_t size() const { return kept.size(); }
};

/// How much a unit of each attribute counts against a unit of distance, in the normalised frame
/// (bounding-box diagonal 1): an attribute difference of 1 / weight costs as much as a distance of
/// one diagonal (Hoppe 1999's attribute quadric, area weighted like the positions). Kinds not
/// listed (joints, skin weights, tangents) are never interpolated: the survivor's are kept. The
/// defaults were chosen by a sweep against meshoptimizer on textured and coloured assets
/// (docs/attributes.md, "Weights"; bench/attr_sweep.sh).
struct AttributeWeights {
  double normal = 0.01;     ///< a normal turned by ~0.17 rad (10 degrees) ~ 0.17 % of the diagonal
  double tex_coord = 0.1;   ///< a UV shift of 0.01 ~ 0.1 % of the diagonal
  double color = 0.1;       ///< a colour change of 0.05 ~ 0.5 % of the diagonal
  double scalar = 0.01;     ///< other per-vertex values
  /// Constraint planes along the seams (wedge changes: UV seams, creases, material boundaries),
  /// weighted as the boundary planes (SimplifyOptions::boundary_weight); 0 disables them. 4.5
  /// with uv 0.1 (was 10 with uv 0.2): on many-seamed atlases (pizza: 58 % of the positions on a
  /// seam) planes of 10 ordered the collapses by seam straightness more than by distance.
  double seam = 4.5;
  /// The normal weight grows with the output's coarseness: it is at least this many times the
  /// spacing of the output's faces, sqrt(surface area / target faces) in diagonals (a face target
  /// is needed; a vertex target counts as twice as many faces). Turning a normal by an angle misplaces
  /// the shading about as much as moving the surface by that angle times a face's size, while a
  /// contraction's positional error grows with the square of its edges' length and its normals'
  /// change only with their length: a fixed weight that keeps the geometry first on fine outputs
  /// lets coarse ones lose small, sharply turning parts (the Duck's beak at 10 %: 9.6 degrees RMS
  /// against 6.3 with this rule; docs/attributes.md, "Weights"). `normal` stays the floor. 0: `normal`
  /// alone (what an explicit normal weight on the command line or in Python sets).
  double normal_per_spacing = 1.0;
  /// The colour weight grows with the output's coarseness too, for the same reason (a colour
  /// changes along an edge with its length): at least this many times the spacing of the output's
  /// faces, but the spacing's share no more than color_spacing_cap. Chosen on the vertex-coloured
  /// assets: a 224-face sphere of random colours keeps its colours at half its faces (colour RMS
  /// 0.043 with `color` alone, 0.019 with this rule, where the weight is 0.29) while a smooth colour
  /// field at half its faces keeps `color` (the spacing is finer: trimesh_reference_vcolor's E rose
  /// to 0.99x meshoptimizer's with a fixed 0.2); docs/attributes.md, "Weights". `color` stays the
  /// floor; 0: `color` alone (what an explicit colour weight on the command line or in Python sets).
  double color_per_spacing = 3.0;
  /// Where the spacing's colour weight stops growing: on the coarsest outputs no placement keeps
  /// colours that vary within a face's size, and a larger weight only bends the geometry (the
  /// sphere at a tenth of its faces: colour RMS 0.309 at 0.4, 0.342 at 0.5, with E 0.17x and 0.40x
  /// meshoptimizer's; 0.93x at 0.64).
  double color_spacing_cap = 0.4;
};

/// The forgetting factor (SimplifyOptions::forget) the command line and the Python module use by
/// default, where the library keeps GH97's quadrics (0): measured on the benchmark meshes
/// (docs/benchmarks.md, "Forgetting").
inline constexpr double kRecommendedForget = 0.85;

struct SimplifyOptions {
  // --- stop criteria: any combination, the first reached wins -----------------------------------
  std::size_t target_faces = 0;     ///< stop at or below this many faces (0 = no face target)
  double target_ratio = 0;          ///< stop at or below ratio * input faces (0 = unused)
  std::size_t target_vertices = 0;  ///< stop at or below this many vertices (0 = unused)
  /// A stop criterion of its own: contract as far as the checks allow (topology, inversion,
  /// components, max_error, locks), as a face target of 0 does on the command line and in
  /// meshoptimizer, CGAL and libigl. The target fields keep 0 = unused, so existing callers are
  /// unchanged; the other criteria still apply (the first reached wins).
  bool as_far_as_possible = false;
  /// Largest allowed contraction error, in distance units: sqrt(Q(v) / weight of Q), i.e. the
  /// weighted RMS distance from the new vertex to the planes it represents. +inf = no limit.
  double max_error = std::numeric_limits<double>::infinity();
  bool max_error_is_relative = false;  ///< max_error is a fraction of the bounding-box diagonal
  /// A bound on the one-sided Hausdorff distance from the output to the input (distance units): no
  /// point of an output face farther than this from the input surface. Each contraction's new
  /// faces are certified against the input (src/core/distance_bound.h) and refused otherwise; the
  /// refit keeps it too. Alone it is a stop criterion: as few faces as the bound allows. +inf = none.
  double max_distance = std::numeric_limits<double>::infinity();
  bool max_distance_is_relative = false;  ///< max_distance is a fraction of the bounding-box diagonal

  // --- the algorithm --------------------------------------------------------------------------
  Weighting weighting = Weighting::Area;
  Placement placement = Placement::Optimal;
  /// Pair threshold t of GH97 §3.2: vertices closer than t are valid pairs too (0 = edges only).
  double threshold = 0;
  bool threshold_is_relative = false;  ///< threshold is a fraction of the bounding-box diagonal
  /// Weight of the boundary constraint planes (GH97 §6); 0 disables them. With exact_border they
  /// rank the contractions only; without, they are GH97's penalty and also pull the placement.
  double boundary_weight = 1;
  bool lock_border = false;  ///< boundary vertices never move
  /// Open borders stay exact (the default): a border vertex never leaves the input's border
  /// polylines (it stays, or slides along its own polyline to the lowest-error point between the
  /// two ends of a border edge), and the refit does not move border vertices. Hard corners
  /// (border ends and junctions, non-manifold edges, locked vertices) are never removed nor moved;
  /// soft corners (a turn above 45 degrees) stay, bit for bit, until the run's error reaches their
  /// distance from the border that would replace them (a scan's jagged hole loses its noise, a
  /// square keeps its corners). false: GH97 §6's penalty alone (boundary_weight), the vertices
  /// may leave the border (`qem simplify --penalty-borders`).
  bool exact_border = true;
  /// Keep every connected component (vertex-connected, counted on the welded working mesh): a
  /// contraction that would leave a component with fewer than its floor of faces (a closed one 4,
  /// an open one 1, or as many as it has if fewer) is refused. Components that a threshold pair
  /// joins are one from then on. false = GH97 as published: a small part may contract to nothing.
  bool keep_components = true;
  /// Prune rule: components whose bounding-box diagonal is below this distance are removed whole
  /// before the first contraction (0 = none). A size rule rather than one tied to the running
  /// error, so what is removed does not depend on the target or the order of contractions.
  double prune_size = 0;
  bool prune_size_is_relative = false;  ///< prune_size is a fraction of the bounding-box diagonal
  /// Per input vertex (empty: none), nonzero = locked: it never moves and is never removed (the
  /// other end of a contraction comes to it). With attributes, a position is locked when any of
  /// its vertices is. The caller's buffer must outlive the call.
  std::span<const std::uint8_t> vertex_lock;
  /// Per input vertex (empty: none), nonzero = protected: with attributes, the seams at it are
  /// never crossed, even by SeamMode::Permissive (meshoptimizer's meshopt_SimplifyVertex_Protect). It
  /// may still be removed, or move, along its seam as any seam vertex does. Same size and lifetime
  /// rules as vertex_lock.
  std::span<const std::uint8_t> vertex_protect;
  /// With attributes: every vertex on a seam (UV seam, normal crease, colour or material boundary,
  /// mirror line: any position with more than one attribute set) is locked as by vertex_lock.
  bool lock_seams = false;
  /// With attributes: what a collapse may do at a seam (SeamMode; `--seams`).
  SeamMode seams = SeamMode::Junctions;
  InversionPolicy inversion = InversionPolicy::Forbid;
  /// A face that turns by more than this (degrees) counts as an inversion; must be < 90.
  double max_normal_turn_degrees = 75;
  /// Refuse edge collapses that break the link condition (non-manifold edges, duplicate faces).
  /// false = GH97 as published: contractions may make non-manifold edges; two faces a contraction
  /// lands on the same three vertices both go (turning the same way or not), so that a closed
  /// input opens no crack.
  bool preserve_topology = true;
  Scheme scheme = Scheme::Passes;
  /// Scheme::Passes finishes in the greedy order once the mesh has at most this many faces: the
  /// heap is then small enough to stay in cache, and the last contractions shape a coarse result
  /// the most (0 = passes to the end).
  std::size_t greedy_below_faces = 20000;
  /// Forgetting (no max_error; with attributes that vary only with forget_attributes): each time the faces
  /// have fallen by this factor since the last time (at the start of a pass, or at once in the greedy order),
  /// every vertex's quadric is made again from its current faces and border edges (as at the
  /// start: GH97 §5-6, HG99 §2) and every pair is costed afresh. GH97's quadrics remember every
  /// plane a vertex ever stood for, so late contractions are ranked by the distance to long-gone
  /// faces; renewed quadrics rank them by what they do to the current surface, as Lindstrom-Turk's
  /// memoryless cost does, which lowers the mean error at the same face count (docs/benchmarks.md,
  /// "Forgetting"). Not below 700 faces, where the mesh's own faces no longer stand for the
  /// surface and the memory keeps its shape. 0 = GH97 as published (never); in [0, 1); the
  /// command line's and Python's default is kRecommendedForget. Off under max_error (the contraction error
  /// bounds the distance to the input only with whole quadrics). The schedule follows the face count, never
  /// the target, so a contraction record still replays to a direct run's mesh.
  double forget = 0;
  /// Forgetting with attributes too: the wedges' attribute quadrics (Hoppe 1999) are renewed from
  /// their current values and the seam planes from the current seams, with the positions'. Off by
  /// default: on the textured and coloured assets it lowers E (geometric mean 0.86x) and most
  /// attribute errors, but shifts error into the attributes on some (the Duck at 50 %: normals
  /// 1.84 against 1.27 degrees; docs/benchmarks.md, "Forgetting with attributes"). Not needed
  /// where no attribute varies (faces' materials alone, a constant colour): nothing to shift.
  bool forget_attributes = false;
  /// Threads for the parts that split without changing the result (0 = all hardware threads).
  unsigned threads = 0;
  /// After the last contraction, refit the vertices to the input surface with the faces fixed
  /// (qem/refit.h, Hoppe et al. 1993) in up to this many rounds; 0 = off (GH97 as published).
  /// Lowers the geometric error at the same face count; `lock_border`, `vertex_lock` and
  /// `max_normal_turn_degrees` apply to it too. With attributes it fits the surface welded by
  /// position and holds every position that carries more than one attribute set (seams, creases,
  /// material boundaries, mirror lines); the other vertices move with their values unchanged
  /// (docs/attributes.md, "Seams, locks and the refit"). An observer's contractions are those made
  /// before it: a replayed level is the unrefitted mesh (refit it with qem::refit to match). The
  /// command line's default is a light refit, refit_rounds = 2 with refit_points_per_vertex = 8
  /// and refit_by_reduction
  /// (what it costs and gains: docs/benchmarks.md).
  unsigned refit_rounds = 0;
  /// The refit's input points per output vertex, 0 = every input vertex (RefitOptions::
  /// points_per_vertex): the time saved grows with the input's vertices per output vertex.
  double refit_points_per_vertex = 0;
  /// The refit follows the reduction (the command line's light refit): none while each output
  /// vertex stands for fewer than 3 input vertices, one round on about 2 points per output vertex
  /// while it stands for fewer than 6, and refit_rounds on refit_points_per_vertex from there.
  /// Fitting the faces to the input's vertices as points raises E when each output vertex stands
  /// for only a few of them (at half the faces the refit raised E by 13-22 %; docs/benchmarks.md,
  /// "Refit variants").
  bool refit_by_reduction = false;
  /// After the last contraction and the refit, repair the places farthest from the input
  /// (core/far_repair.h): flip an edge (Hoppe et al. 1993 §4.3's edge swap), move an interior
  /// vertex toward the input points far from it, or relocate a vertex (split the farthest place's
  /// edge or face at the input, collapse the flattest vertex; on meshes without attributes,
  /// materials or vertex properties), where that lowers the local Hausdorff distance without
  /// raising the local share of E. The topology stays (Euler characteristic, components); the face
  /// count too, but for a relocation that splits a border edge with no border vertex to spare (one
  /// face fewer, at most one face in 256); the vertex count too, but for a split of both sides of a
  /// crack (two coincident border edges: a vertex more; never with target_vertices). Border
  /// vertices stay on the input's border, seams, locked vertices and material boundaries as they
  /// are. As with the refit, an observer's contractions are those made before it. The command
  /// line's default, with its refit (what it costs and gains: docs/benchmarks.md, "Far places").
  bool far_repair = false;

  /// With attributes (MeshView::attributes), their weights in the error.
  AttributeWeights attribute_weights;
  /// With attributes: after the last contraction (and the refit), fit the values of every vertex
  /// off the seams, by least squares, to the input's attributes at the output's points closest to
  /// points of the input's faces (Hoppe 1996 §4.2; docs/attributes.md, "The attribute fit").
  /// Positions and faces are not changed. Off by default: it keeps the input's attributes and
  /// faces through the run and adds a projection per input face, whose cost on a large mesh was
  /// not measured on a quiet machine yet (docs/attributes.md, docs/benchmarks.md).
  bool fit_attributes = false;

  /// Fill SimplifyResult::output_vertex_of_input (one entry per input vertex).
  bool map_input_vertices = false;

  /// Two-sided sheets. An input that makes a sheet two-sided with a reversed copy of each face (the
  /// same three points turning the other way) has no open edge there: welded by position, each of
  /// the sheet's edges has a face and its twin. The run simplifies one face of each such pair (a
  /// duplicate, SimplifyResult::dropped_duplicate_faces); this says which output faces whose input
  /// face had a reversed twin get their twin back (SimplifyResult::twin_faces). The twins count in
  /// the face target (and their vertices, with normals, in a vertex target): where they would pass
  /// it the run is made again to a lower target. With All, target_ratio is of the input's faces
  /// with their twins (both sides; else of the faces simplified). A partitioned run whose parts
  /// find duplicate faces runs whole instead (qem/partition.h). Not with an observer that wants
  /// contractions (a record describes the contractions alone).
  TwoSided two_sided = TwoSided::Rims;
};

struct SimplifyResult {
  Mesh mesh;                        ///< the approximation; unreferenced vertices dropped
  std::size_t input_faces = 0;      ///< after dropping degenerate and duplicate input faces
  std::size_t input_vertices = 0;   ///< referenced vertices of the input
  std::size_t contractions = 0;
  std::size_t virtual_pairs = 0;    ///< non-edge pairs found with the threshold t
  /// Candidate contractions popped from the heap and refused (each may be retried later).
  std::size_t rejected_topology = 0, rejected_inversion = 0, rejected_error = 0;
  std::size_t rejected_distance = 0;  ///< refused by max_distance
  /// With max_distance: the largest distance from the output to the input over the certified
  /// samples of every output face (after the refit), in distance units; at most max_distance.
  double output_to_input_distance = 0;
  double output_to_input_distance_relative = 0;  ///< the same over the bounding-box diagonal
  /// ... and refused because a connected component would have dropped below its floor
  /// (SimplifyOptions::keep_components).
  std::size_t rejected_component = 0;
  /// Connected components (vertex-connected, of the welded working mesh) of the input and of the
  /// output, and how many the prune rule removed (SimplifyOptions::prune_size).
  std::size_t input_components = 0, output_components = 0, pruned_components = 0;
  /// Largest contraction error performed (distance units). With forgetting (SimplifyOptions::
  /// forget) each error is measured against the quadrics as last renewed, that is from the surface
  /// of then, not from the input (output_to_input_distance and qem::measure give that).
  double max_error = 0;
  double max_error_relative = 0;    ///< the same over the bounding-box diagonal
  StopReason stop_reason = StopReason::TargetReached;
  std::string stop_detail;          ///< human-readable explanation of the stop
  /// With refit_rounds > 0: the refit's area-weighted RMS distance from the input's vertices (or
  /// those it sampled) to the output, before and after it (model units), and the rounds it kept.
  /// With far_repair, the after may be an upper bound of it (the distances to each point's face
  /// of the refit's projection before its last round, whose faces that round keeps), taken before
  /// the repair.
  double refit_rms_before = 0, refit_rms_after = 0;
  std::size_t refit_rounds = 0;
  /// The normal weight the run used (AttributeWeights::normal, after normal_per_spacing); 0 when the
  /// input has no normals.
  double normal_weight = 0;
  /// The colour weight the run used (AttributeWeights::color, after color_per_spacing); 0 when the
  /// input has no colours.
  double color_weight = 0;
  /// With far_repair: the edges flipped (each output face keeps its face_source and material) and
  /// the vertices moved.
  std::size_t edge_flips = 0, vertex_moves = 0;
  /// With far_repair: vertices taken from the flattest places to the farthest (see far_repair; the
  /// provenance follows: a relocated vertex's source is the input vertex it stands at or nearest).
  std::size_t vertex_relocations = 0;
  /// Input faces left out: degenerate (a repeated corner) and duplicates (kept once).
  std::size_t dropped_degenerate_faces = 0, dropped_duplicate_faces = 0;
  /// With SimplifyOptions::two_sided: the reversed twins put back, after the other faces (counted
  /// in the mesh's faces; each one's face_source is the input's reversed twin of its front face's,
  /// and with normals its new vertices' vertex_source their front vertex's).
  std::size_t twin_faces = 0;

  /// Provenance, so that callers can carry their own per-vertex and per-face data across: for
  /// each output vertex, the input vertex whose position it started from (the survivor of its
  /// contractions); for each output face, the input face it is.
  std::vector<std::uint32_t> vertex_source, face_source;
  /// With SimplifyOptions::map_input_vertices: for each input vertex, the output vertex it was
  /// contracted into, kUnmapped for unreferenced vertices and for parts that vanished.
  std::vector<std::uint32_t> output_vertex_of_input;
  static constexpr std::uint32_t kUnmapped = 0xffffffffu;
};

/// One contraction as it is made: input vertex `removed` went into input vertex `kept`, which now
/// stands at `position` (output coordinates), at `error` (distance units); `dead_faces` are the
/// input faces that died with it.
struct Contraction {
  std::uint32_t kept, removed;
  double position[3];
  double error;
  std::span<const std::uint32_t> dead_faces;
};

/// Watches a run, as CGAL's edge-collapse visitor does: told when it starts, of each contraction,
/// and of its progress, which it may cancel. Every method does nothing by default.
class SimplifyObserver {
 public:
  virtual ~SimplifyObserver() = default;
  /// Whether on_contraction is wanted. The contractions are then made one after another on the
  /// calling thread (the output is the same bytes), so say yes only when needed.
  virtual bool wants_contractions() const { return false; }
  /// The input faces the run starts from (degenerate and duplicate ones left out), in no order.
  virtual void on_start(std::span<const std::uint32_t> /*input_faces*/) {}
  virtual void on_contraction(const Contraction& /*contraction*/) {}
  /// Called every few thousand contractions with the fraction done (0..1, 1 at the end); return
  /// false to cancel the run (the result is the mesh so far, StopReason::Cancelled).
  virtual bool on_progress(double /*fraction*/) { return true; }
};

/// Keeps the whole contraction sequence in `log` (qem/progressive.h makes records of it).
class ContractionRecorder : public SimplifyObserver {
 public:
  ContractionLog log;
  bool wants_contractions() const override { return true; }
  void on_start(std::span<const std::uint32_t> input_faces) override;
  void on_contraction(const Contraction& contraction) override;
};

/// Calls a function with the fraction done; it returns false to cancel.
class ProgressCallback : public SimplifyObserver {
 public:
  explicit ProgressCallback(std::function<bool(double)> fn) : fn_(std::move(fn)) {}
  bool on_progress(double fraction) override { return fn_(fraction); }

 private:
  std::function<bool(double)> fn_;
};

/// Throws qem::Error naming the first option out of its range, or a missing stop criterion.
/// `simplify` checks its options first with it; callers can check before loading a large mesh.
void check_options(const SimplifyOptions& options);

/// Simplifies a mesh. Input positions are never normalised in the output: vertices that did not
/// move keep their exact input coordinates. Deterministic: the same input and options give the
/// same output. `observer` (may be null) watches the run. Throws qem::Error on invalid options,
/// an out-of-range index or a non-finite coordinate.
SimplifyResult simplify(MeshView input, const SimplifyOptions& options, SimplifyObserver* observer = nullptr);

/// The same, consuming the input: its index array is released (left empty) as soon as the
/// simplifier holds its own copy of the faces, and its attributes' values (left empty, names and
/// kinds kept) once it holds its own copy of them, which lowers the peak memory on large meshes.
/// The positions are kept: unmoved vertices are copied from them at the end.
SimplifyResult simplify(Mesh&& input, const SimplifyOptions& options, SimplifyObserver* observer = nullptr);

}  // namespace qem
