// Surface simplification by iterative pair contraction with quadric error metrics
// (Garland & Heckbert 1997, "GH97"; area weighting from Heckbert & Garland 1999, "HG99").
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "qem/mesh.h"
#include "qem/refit.h"

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
/// The value called `name` (a to_string name, which is also the command line's: "area", "off"):
/// true and `out` set, or false and `out` unchanged if no value has that name.
bool from_string(const std::string& name, Weighting& out);
bool from_string(const std::string& name, Placement& out);
bool from_string(const std::string& name, Scheme& out);
bool from_string(const std::string& name, InversionPolicy& out);
/// The names of all values of an option enum (Weighting, Placement, Scheme, InversionPolicy; no
/// other is defined), in declaration order: the choices a front end offers.
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

struct SimplifyOptions {
  // --- stop criteria: any combination, the first reached wins -----------------------------------
  std::size_t target_faces = 0;     ///< stop at or below this many faces (0 = no face target)
  double target_ratio = 0;          ///< stop at or below ratio * input faces (0 = unused)
  std::size_t target_vertices = 0;  ///< stop at or below this many vertices (0 = unused)
  /// Largest allowed contraction error, in distance units: sqrt(Q(v) / weight of Q), i.e. the
  /// weighted RMS distance from the new vertex to the planes it represents. +inf = no limit.
  double max_error = std::numeric_limits<double>::infinity();
  bool max_error_is_relative = false;  ///< max_error is a fraction of the bounding-box diagonal

  // --- the algorithm --------------------------------------------------------------------------
  Weighting weighting = Weighting::Area;
  Placement placement = Placement::Optimal;
  /// Pair threshold t of GH97 §3.2: vertices closer than t are valid pairs too (0 = edges only).
  double threshold = 0;
  bool threshold_is_relative = false;  ///< threshold is a fraction of the bounding-box diagonal
  /// Penalty weight of the boundary constraint planes (GH97 §6); 0 disables them.
  double boundary_weight = 1;
  bool lock_border = false;  ///< boundary vertices never move
  InversionPolicy inversion = InversionPolicy::Forbid;
  /// A face that turns by more than this (degrees) counts as an inversion; must be < 90.
  double max_normal_turn_degrees = 75;
  /// Refuse edge collapses that break the link condition (non-manifold edges, duplicate faces).
  bool preserve_topology = true;
  Scheme scheme = Scheme::Passes;
  /// Scheme::Passes finishes in the greedy order once the mesh has at most this many faces: the
  /// heap is then small enough to stay in cache, and the last contractions shape a coarse result
  /// the most (0 = passes to the end).
  std::size_t greedy_below_faces = 20000;
  /// Threads for the parts that split without changing the result (0 = all hardware threads).
  unsigned threads = 0;
  /// After the last contraction, refit the vertices to the input surface with the faces fixed
  /// (qem/refit.h, Hoppe et al. 1993) in up to this many rounds; 0 = off (GH97 as published).
  /// Lowers the geometric error at the same face count; `lock_border` and
  /// `max_normal_turn_degrees` apply to it too. The record (if any) holds the contractions only:
  /// a replayed level is the unrefitted mesh (refit it with qem::refit to match). The command
  /// line's default is a light refit, refit_rounds = 1 with refit_points_per_vertex = 2, which
  /// puts E under the best peer's on the benchmark meshes for 11-14 % of the run's time on the
  /// 1.3M-face sphere to 10 % (about 0.2 s), 3 % to 1 %.
  unsigned refit_rounds = 0;
  /// The refit's input points per output vertex, 0 = every input vertex (RefitOptions::
  /// points_per_vertex). 4-8 keep most of the refit's gain; the time saved grows with the input's
  /// vertices per output vertex (docs/benchmarks.md).
  double refit_points_per_vertex = 0;

  /// If set, every contraction is appended to this log (cleared first).
  ContractionLog* record = nullptr;

  /// Called every so often with the fraction done (0..1); return false to cancel.
  std::function<bool(double)> progress;
};

struct SimplifyResult {
  Mesh mesh;                        ///< the approximation; unreferenced vertices dropped
  std::size_t input_faces = 0;      ///< after dropping degenerate input faces
  std::size_t input_vertices = 0;   ///< referenced vertices of the input
  std::size_t contractions = 0;
  std::size_t virtual_pairs = 0;    ///< non-edge pairs found with the threshold t
  /// Candidate contractions popped from the heap and refused (each may be retried later).
  std::size_t rejected_topology = 0, rejected_inversion = 0, rejected_error = 0;
  double max_error = 0;             ///< largest contraction error performed (distance units)
  double max_error_relative = 0;    ///< the same over the bounding-box diagonal
  StopReason stop_reason = StopReason::TargetReached;
  std::string stop_detail;          ///< human-readable explanation of the stop
  /// With refit_rounds > 0: the refit's area-weighted RMS distance from the input's vertices (or
  /// those it sampled) to the output, before and after it (model units), and the rounds it kept.
  double refit_rms_before = 0, refit_rms_after = 0;
  std::size_t refit_rounds = 0;
};

/// The refit options `simplify` uses for `options` (qem/refit.h): the same rounds, points per
/// vertex, border lock, face turn limit and threads. `qem lod` refits each level with them, as
/// `simplify` would.
RefitOptions refit_options(const SimplifyOptions& options);

/// Simplifies a mesh. Input positions are never normalised in the output: vertices that did not
/// move keep their exact input coordinates. Deterministic: the same input and options give the
/// same output. Throws qem::Error on invalid options, an out-of-range index or a
/// non-finite coordinate.
SimplifyResult simplify(MeshView input, const SimplifyOptions& options);

/// The same, consuming the input: its index array is released (left empty) as soon as the
/// simplifier holds its own copy of the faces, which lowers the peak memory on large meshes.
/// The positions are kept: unmoved vertices are copied from them at the end.
SimplifyResult simplify(Mesh&& input, const SimplifyOptions& options);

}  // namespace qem
