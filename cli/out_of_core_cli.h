// The out-of-core branch of `qem simplify` (qem/out_of_core.h): its options, the decision, the
// progress display and the JSON summary. Kept apart from cmd_simplify.cpp, which only calls it.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "qem/simplify.h"

namespace qem::cli {

struct OutOfCoreArgs {
  std::string memory_limit;  ///< --memory-limit, e.g. "2G"; empty = automatic
  std::string temp_dir;      ///< --temp-dir; empty = $TMPDIR, else the output's folder
  double phase2_size = 32;   ///< --phase2-size: phase 2 starts from at most ~this many times the target
  std::string partition = "auto";  ///< --partition, for phase 2: auto, off or a number of parts
};

void add_out_of_core_options(CLI::App* sub, OutOfCoreArgs& args);

/// True when the input should be simplified out of core: a binary PLY / STL whose in-memory run
/// would exceed the memory limit.
bool wants_out_of_core(const std::string& input, const OutOfCoreArgs& args);

struct OutputArgs {
  bool ascii = false, json = false, quiet = false, double_values = false;
  std::size_t target_faces = 0;
};

/// Runs simplify_out_of_core and writes the output atomically; returns the exit status.
int run_out_of_core(const std::string& input, const std::string& output, const SimplifyOptions& options,
                    const OutOfCoreArgs& args, const OutputArgs& out);

}  // namespace qem::cli
