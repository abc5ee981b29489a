// The simplifier's pipeline (GH97 §4's algorithm summary), without the refit, which follows it
// outside the core (src/simplify.cpp).
#pragma once

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "core/wedges.h"
#include "qem/simplify.h"

namespace qem::core {

struct Context;
struct PassState;

/// What a caller of the core may ask besides the options.
struct RunHooks {
  SimplifyObserver* observer = nullptr;
  /// The caller's index array, released once the core holds its own copy of the faces.
  std::vector<std::uint32_t>* consumed_indices = nullptr;
  /// The caller's attributes, whose values are released once the wedges hold their own copy (their
  /// names and kinds stay: the output's attributes are named after them).
  std::vector<VertexAttribute>* consumed_attributes = nullptr;
  /// Called with the input just before its indices are released (what needs the input's faces).
  std::function<void(MeshView)> before_release;
  /// Filled with WorkingMesh::reversed_twins. When there are any, the caller's index array and
  /// attributes are kept (not consumed): it may run again, to a target lowered for the twins it adds.
  std::vector<std::pair<std::uint32_t, std::uint32_t>>* reversed_twins = nullptr;
  /// Fill SimplifyResult::output_vertex_of_input even when the options do not ask for it.
  bool map_input_vertices = false;
  /// With attributes: filled with what the refit needs of each output vertex (wedges.h).
  WedgeRefitData* wedge_refit = nullptr;
  /// For the tests: called after each band of a pass with the state the lists are read through,
  /// and with an empty one after the greedy order (alone, or as the passes' tail).
  std::function<void(const Context&, const PassState&)> after_band;
};

SimplifyResult run(MeshView input, const SimplifyOptions& options, const RunHooks& hooks);

}  // namespace qem::core
