// Small helpers shared by the subcommands: loading, timing, memory, paths, JSON numbers.
#pragma once

#include <chrono>
#include <string>

#include "qem/io.h"

namespace qem::cli {

/// Monotonic seconds since construction (steady_clock, as the bench harness requires).
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

/// load_mesh, then each of the reader's warnings on stderr as "qem: warning: <text>", so a file read
/// leniently says so whichever command read it (`qem info` lists them in its report instead). Not
/// silenced by --quiet, which is about progress and summaries, not about what happened to the input.
Mesh load_input(const std::string& path, const LoadOptions& options = {}, LoadReport* report = nullptr);

/// CPU seconds used by this process so far (user + system).
double process_cpu_seconds();

/// Peak resident set size of this process in MB (VmHWM), or 0 if unknown.
double peak_rss_mb();

/// True if both paths name the same existing file (so writing one would destroy the other).
bool same_file(const std::string& a, const std::string& b);

/// Throws qem::Error if writing `output` would overwrite `input` and `force` is not set: a run
/// must never destroy its own input by accident.
void refuse_to_overwrite(const std::string& input, const std::string& output, bool force);

/// Help of `--double` for the commands that write a mesh made from an input mesh.
inline constexpr const char* kDoubleOutputHelp =
    "Write PLY values as double (default: double when the input is a PLY that stores doubles, as "
    "georeferenced scans do; float otherwise)";

/// A JSON string literal: quotes, backslashes and control characters escaped (paths may hold them).
std::string json_string(const std::string& s);

/// A number for a JSON document: shortest round-trip form, `null` for NaN/inf.
std::string json_number(double x);

}  // namespace qem::cli
