// `qem simplify --partition auto|off|N` (qem/partition.h): the option, the choice of the number of
// parts, and the partitioned run with its progress line. Kept apart from cmd_simplify.cpp, which
// only calls it.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "qem/partition.h"
#include "qem/simplify.h"

namespace qem::cli {

struct PartitionArgs {
  std::string partition = "auto";  ///< --partition: auto, off, or a number of parts
};

void add_partition_option(CLI::App* sub, PartitionArgs& args);

/// The number --partition asks for: 0 for `auto`, 1 for `off`, else N (1 to 4096); throws
/// qem::Error for anything else.
unsigned asked_parts(const std::string& partition);

/// The number of parts for this run, 1 = in core: `off` and `1` give 1; `auto` gives
/// automatic_parts(faces) when the mesh and options allow a partition (partition_refusal) and no
/// record is kept, else 1; a number N > 1 gives N, and throws qem::Error saying why when the mesh
/// or options do not allow it.
unsigned choose_parts(const PartitionArgs& args, MeshView mesh, const SimplifyOptions& options, bool record);

/// simplify_partitioned with a progress line on stderr ("part k of N") when `show_progress`.
SimplifyResult run_partitioned(MeshView mesh, const SimplifyOptions& options, unsigned parts, bool show_progress,
                               PartitionReport* report);

}  // namespace qem::cli
