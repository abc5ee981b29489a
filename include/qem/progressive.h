// Progressive meshes from one simplification run (GH97 §3: "one run yields M_n, M_n-1, ..., M_g").
//
// A Record is the base mesh M_n (the input as the simplifier saw it) plus the ordered contraction
// sequence of one `simplify` run. Replaying a prefix of it rebuilds the exact mesh that `simplify`
// would have returned had it stopped there: same vertices in the same order, same coordinates to
// the bit, same faces. So one run to the smallest target gives every coarser-than-input level
// (an LOD chain) at the cost of one simplification plus a linear pass per level.
//
// The on-disk form is a small versioned little-endian binary file, specified in
// docs/record-format.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "qem/error.h"
#include "qem/mesh.h"
#include "qem/simplify.h"

namespace qem {

/// One simplification run, self-contained: needs no input file to replay.
/// Every id is a *base* id: base vertex i is the i-th vertex the run used (referenced by a
/// non-degenerate face), in input order; base face j is the j-th face the run started from, in
/// input order. Both orders are the input's, so meshes rebuilt from a record list vertices and
/// faces exactly as `simplify` does.
struct Record {
  Mesh base;  ///< M_n: positions of the used vertices, the initial faces (no vertex properties)
  // One entry per contraction, in the order the simplifier made them:
  std::vector<std::uint32_t> kept;     ///< base vertex that survives
  std::vector<std::uint32_t> removed;  ///< base vertex merged into `kept` (gone from then on)
  std::vector<double> position;        ///< 3 per contraction: where `kept` went, output coordinates
  std::vector<double> error;           ///< contraction error (model units, as SimplifyResult::max_error)
  /// Base faces that died in contraction i: dead_faces[dead_begin[i] .. dead_begin[i+1]).
  std::vector<std::uint32_t> dead_begin{0};
  std::vector<std::uint32_t> dead_faces;
  /// The input file stored double coordinates (a double PLY), so `qem replay` writes doubles too,
  /// as `qem simplify` does for that input. Header flag kRecordFlagDoubleInput.
  bool double_input = false;

  std::size_t size() const { return kept.size(); }
  /// Faces of the fully simplified mesh M_g (after every contraction).
  std::size_t final_faces() const { return base.face_count() - dead_faces.size(); }
};

/// Builds a record from the mesh given to `simplify` and the ContractionLog it filled.
/// Throws qem::Error if the log does not belong to that mesh.
Record make_record(MeshView input, const ContractionLog& log);

/// Checks every invariant replay relies on (ids in range, no vertex removed twice, no face dying
/// twice, finite coordinates and errors). Throws qem::Error starting with `name`.
void validate_record(const Record& record, const std::string& name = "record");

/// The file format of docs/record-format.md, version kRecordVersion.
inline constexpr std::uint32_t kRecordVersion = 1;
/// Header flag bit 0: Record::double_input. Other bits are reserved; readers reject them.
inline constexpr std::uint32_t kRecordFlagDoubleInput = 1;
std::string serialize_record(const Record& record);
/// Parses and validates a record held in memory; `name` is used in error messages. Checks the
/// sizes the header announces against the bytes present before allocating anything.
Record parse_record(std::string_view bytes, const std::string& name);
/// Writes atomically (temporary file beside `path`, then rename).
void write_record(const std::string& path, const Record& record);
Record read_record(const std::string& path);

/// The mesh after the shortest prefix of contractions that leaves at most `target_faces` faces
/// (all of them if the run never got that low). Equal, vertex for vertex and bit for bit, to
/// `simplify(input, options with target_faces)` for any target_faces >= record.final_faces() when
/// the record was made by `simplify` with the same options and a smaller or equal target.
Mesh replay(const Record& record, std::size_t target_faces);

/// One level of an LOD chain.
struct ReplayLevel {
  Mesh mesh;
  std::size_t target_faces = 0;
  std::size_t contractions = 0;  ///< length of the prefix applied
  double max_error = 0;          ///< largest contraction error in that prefix (model units)
};

/// Several targets in one pass over the record (any order; the result follows `targets`).
std::vector<ReplayLevel> replay_levels(const Record& record, std::span<const std::size_t> targets);

}  // namespace qem
