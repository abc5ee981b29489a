// A switch for the tests: when it is on, the simplifier verifies, after each band of a pass, that
// the vertex lists it reads are the mesh's own (Simplifier::check_lists), and throws
// std::logic_error at the first that is not. Each check walks the whole mesh, so it is for small
// test meshes only; off, it costs one branch a band.
#pragma once

namespace qem::core {

inline bool check_invariants = false;

}  // namespace qem::core
