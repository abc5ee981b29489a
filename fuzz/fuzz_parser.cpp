// libFuzzer target for one mesh reader, chosen at compile time by QEM_FUZZ_FORMAT (Obj, Ply, Stl or
// Off; fuzz/CMakeLists.txt builds one executable per format). io.h promises that a reader either
// returns a valid mesh or throws qem::Error: anything else (another exception, a crash, a sanitizer
// report, a hang past -timeout) is a finding.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>

#include "fuzz_checks.h"
#include "qem/error.h"
#include "qem/io.h"

#ifndef QEM_FUZZ_FORMAT
#error "define QEM_FUZZ_FORMAT to Obj, Ply, Stl or Off"
#endif

namespace {

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "qem fuzz finding: %s\n", what.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr qem::FileFormat kFormat = qem::FileFormat::QEM_FUZZ_FORMAT;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  qem::LoadOptions options;
  options.format = kFormat;
  options.keep_vertex_properties = true;  // exercise the property paths too
  qem::Mesh mesh;
  try {
    mesh = qem::parse_mesh(bytes, kFormat, "fuzz", options);
  } catch (const qem::Error&) {
    return 0;  // the documented way to reject bad input
  }
  // Other exceptions (std::bad_alloc from an unchecked count included) propagate: libFuzzer reports
  // an uncaught exception as a crash.
  const std::string problem = qem::fuzz::check_mesh(mesh);
  if (!problem.empty()) fail(problem);

  // Whatever a reader accepts, the writers must write and the reader must read back.
  for (bool binary : {false, true}) {
    const std::string out = qem::serialize_mesh(mesh, kFormat, binary);
    qem::Mesh again;
    try {
      again = qem::parse_mesh(out, kFormat, "fuzz-roundtrip", options);
    } catch (const qem::Error& e) {
      fail(std::string("re-reading written output failed: ") + e.what());
    }
    if (again.face_count() != mesh.face_count())
      fail("round trip changed the face count from " + std::to_string(mesh.face_count()) + " to " +
           std::to_string(again.face_count()));
    if (kFormat == qem::FileFormat::Obj || kFormat == qem::FileFormat::Off) break;  // no binary variant
  }
  return 0;
}
