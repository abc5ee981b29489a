// libFuzzer target for one mesh reader, chosen at compile time by QEM_FUZZ_FORMAT (Obj, Ply, Stl,
// Off or Gltf; fuzz/CMakeLists.txt builds one executable per format). io.h promises that a reader either
// returns a valid mesh or throws qem::Error: anything else (another exception, a crash, a sanitizer
// report, a hang past -timeout) is a finding.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>

#include "fuzz_checks.h"
#include "qem/io.h"

#ifndef QEM_FUZZ_FORMAT
#error "define QEM_FUZZ_FORMAT to Obj, Ply, Stl, Off or Gltf"
#endif

namespace {

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "qem fuzz finding: %s\n", what.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  // Exceptions other than qem::Error (std::bad_alloc from an unchecked count included) propagate:
  // libFuzzer reports an uncaught exception as a crash.
  const std::string problem = qem::fuzz::check_parse(bytes, qem::FileFormat::QEM_FUZZ_FORMAT);
  if (!problem.empty()) fail(problem);
  return 0;
}
