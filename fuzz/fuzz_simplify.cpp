// libFuzzer target for the simplifier: small meshes full of the degenerate cases GH97 §4 has to
// survive (coincident, collinear, coplanar points, non-manifold and duplicate faces) with random
// SimplifyOptions. simplify.h promises a valid mesh or a qem::Error, and the same output for the same
// input; the invariants live in fuzz_checks.h so regression tests check exactly the same things.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz_checks.h"
#include "qem/error.h"
#include "qem/simplify.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const qem::fuzz::SimplifyCase c = qem::fuzz::decode_simplify_case(data, size);
  qem::SimplifyResult first, second;
  try {
    first = qem::simplify(c.mesh, c.options);
  } catch (const qem::Error&) {
    return 0;  // invalid options are rejected this way
  }
  std::string problem = qem::fuzz::check_simplify_result(c, first);
  // Determinism: a second run must give the same bytes (catches uninitialised reads and
  // pointer-order dependence).
  if (problem.empty()) {
    second = qem::simplify(c.mesh, c.options);
    if (second.mesh.indices != first.mesh.indices || second.mesh.positions != first.mesh.positions)
      problem = "two runs on the same input gave different meshes";
  }
  if (!problem.empty()) {
    std::fprintf(stderr, "qem fuzz finding: %s (%zu vertices, %zu faces in; %zu faces out)\n",
                 problem.c_str(), c.mesh.vertex_count(), c.mesh.face_count(), first.mesh.face_count());
    std::abort();
  }
  return 0;
}
