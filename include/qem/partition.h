// Simplifying a large mesh part by part, so that every core (or every MPI rank) has work: the
// partitioned scheme of meshoptimizer's Nanite-style hierarchy (demo/clusterlod.h) reduced to one
// level. The faces are cut along a Morton curve of their centroids into parts of equal face count;
// each part is simplified on its own with the vertices it shares with another part locked, so the
// parts still meet vertex for vertex; the parts are welded on those vertices (exactly: they never
// moved) and one in-core pass over the merged mesh, with the cut unlocked, reaches the target and
// removes the dense strips the locks left along the cuts; the refit, if asked, fits the result to
// the input as simplify's does. With attributes (wedges, qem/mesh.h) the same, the cut found by
// position: every wedge at a position two parts use is locked (docs/parallel.md).
//
// The parts do not depend on the thread count, and each part's simplification gives the same bytes
// on any thread count (qem/simplify.h), so the result depends on the number of parts only, never on
// --threads or on which process simplified which part (threads or MPI ranks).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "qem/mesh.h"
#include "qem/simplify.h"

namespace qem {

/// One part of a partitioned mesh, in its own vertex numbering.
struct MeshPart {
  /// Positions and faces of the part only, with the input's attribute rows of its vertices and
  /// the input's materials of its faces (indices into the input's material names).
  Mesh mesh;
  /// Per part vertex: 1 = locked (shared with another part, or locked by the caller). With
  /// attributes a position is shared: every wedge at a position two parts use is locked.
  std::vector<std::uint8_t> locked;
  /// Per part vertex (empty: the caller protects none): SimplifyOptions::vertex_protect.
  std::vector<std::uint8_t> protect;
  std::vector<std::uint32_t> input_vertex;  ///< per part vertex: the input vertex it is
  std::vector<std::uint32_t> input_face;    ///< per part face: the input face it is
  /// This part's share of the target plus its locked vertices (the faces a locked cut keeps
  /// must not be taken from the part's interior); 0 = unused.
  std::size_t target_faces = 0, target_vertices = 0;
};

/// What simplifying a part gave, in the part's numbering: enough to weld and finish.
struct MeshPartResult {
  Mesh mesh;
  std::vector<std::uint32_t> vertex_source;           ///< per output vertex: the part vertex
  std::vector<std::uint32_t> face_source;             ///< per output face: the part face
  std::vector<std::uint32_t> output_vertex_of_input;  ///< per part vertex (kUnmapped: gone)
  std::size_t input_faces = 0, contractions = 0;
  std::size_t rejected_topology = 0, rejected_inversion = 0, rejected_error = 0, rejected_component = 0;
  std::size_t dropped_duplicate_faces = 0;
  double max_error = 0;  ///< model units
};

/// Simplifies one part with `options`' rules: its own target, its locked vertices, no refit, on
/// options.threads threads. The same bytes on any thread count and in any process.
MeshPartResult simplify_part(const MeshPart& part, const SimplifyOptions& options);

/// Runs simplify_part on every part, results in the parts' order. The default runs them on
/// std::threads; an MPI front end (qem-mpi) sends them to its ranks instead.
using PartRunner = std::function<void(std::span<const MeshPart> parts, const SimplifyOptions& options,
                                      std::span<MeshPartResult> results)>;

struct PartitionOptions {
  /// Number of parts; 0 = automatic_parts(faces).
  unsigned parts = 0;
  /// Empty: the parts are simplified on options.threads std::threads, one part per thread.
  PartRunner run_parts;
  /// Called from the calling thread as parts finish (with the default runner) and before the final
  /// pass; returning false cancels (qem::Error "cancelled").
  std::function<bool(unsigned parts_done, unsigned parts)> progress;
};

struct PartitionReport {
  unsigned parts = 0;
  std::size_t shared_vertices = 0;  ///< input vertices on a cut (locked in the parts)
  std::size_t merged_faces = 0;     ///< faces of the welded parts, the final pass's input
  double split_seconds = 0, parts_seconds = 0, final_seconds = 0;  ///< wall
  /// CPU seconds of the parts (default runner only): all of them, and those of the thread that had
  /// the most. On a loaded machine, where wall times say little, their difference shows how much
  /// the threads shared the work.
  double parts_cpu_seconds = 0, busiest_thread_cpu_seconds = 0;
};

/// Parts for an input of `faces` faces when the caller leaves the choice: 1 (no partition) below
/// 1,000,000 faces, else the largest power of two that leaves each part at least 500,000 faces, at
/// most 64. A function of the face count only, so a command line gives the same bytes on any
/// machine and any --threads.
unsigned automatic_parts(std::size_t faces);

/// Empty when `input` and `options` can be simplified part by part, else why not (an error limit,
/// a distance bound, a pair threshold, pruning, a target of 0, or no face or vertex target).
/// Attributes and face materials are carried (the parts have their rows, the cut is found by
/// position so that no seam on it opens, the final pass and refit treat them as simplify does).
std::string partition_refusal(MeshView input, const SimplifyOptions& options);

/// Simplifies `input` in `partition.parts` parts (see the top of this file) to the target of
/// `options`; `options.threads` threads (0 = all). Throws qem::Error when partition_refusal is not
/// empty, on invalid options or input, and on a cancel. With one part it is simplify(). When the
/// parts dropped duplicate faces and options.two_sided is not None, the result is simplify()'s
/// too (report->parts 1): a two-sided sheet's twins are put back by the whole run only.
SimplifyResult simplify_partitioned(MeshView input, const SimplifyOptions& options,
                                    const PartitionOptions& partition = {}, PartitionReport* report = nullptr);

/// The cut itself (also used by the MPI front end, which runs the parts elsewhere and finishes with
/// finish_partitioned): the parts with their targets. An input with face materials and no
/// attribute gives parts with one constant attribute, "qem:materials", which takes the materials
/// through the parts' runs (simplify keeps materials apart on its attribute path) and which
/// finish_partitioned takes off again.
std::vector<MeshPart> split_mesh(MeshView input, const SimplifyOptions& options, unsigned parts,
                                 PartitionReport* report = nullptr);

/// Welds the simplified parts of split_mesh(input, options, ...) and runs the final pass.
SimplifyResult finish_partitioned(MeshView input, const SimplifyOptions& options, std::span<const MeshPart> parts,
                                  std::span<const MeshPartResult> results, PartitionReport* report = nullptr);
/// The same, taking the parts and their results over: they are freed once welded, before the refit
/// and the repair against the whole input, whose tree and points are the run's peak of memory
/// (the parts hold the input's faces and vertices again).
SimplifyResult finish_partitioned(MeshView input, const SimplifyOptions& options, std::vector<MeshPart>&& parts,
                                  std::vector<MeshPartResult>&& results, PartitionReport* report = nullptr);

}  // namespace qem
