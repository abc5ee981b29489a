#include "partition_cli.h"

#include <cstdio>

#include "qem/error.h"

namespace qem::cli {

void add_partition_option(CLI::App* sub, PartitionArgs& args) {
  sub->add_option("--partition", args.partition,
                  "Simplify part by part, the parts side by side on the threads: auto (default: from 1M faces, "
                  "parts of at least 500k faces, a power of two up to 64; never for "
                  "--max-error, --max-distance, --threshold, --prune, a target of 0 or --record), off, or a number of parts. "
                  "Each part is simplified with the vertices it shares with others locked, then the parts are "
                  "welded and one pass over the whole reaches the target (docs/parallel.md). The output "
                  "depends on the number of parts, never on --threads")
      ->capture_default_str();
}

unsigned asked_parts(const std::string& partition) {
  if (partition == "auto") return 0;
  if (partition == "off") return 1;
  std::size_t used = 0;
  unsigned long parts = 0;
  try {
    parts = std::stoul(partition, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != partition.size() || parts == 0 || parts > 4096)
    throw Error("--partition must be auto, off or a number of parts from 1 to 4096, not '" + partition + "'");
  return unsigned(parts);
}

unsigned choose_parts(const PartitionArgs& args, MeshView mesh, const SimplifyOptions& options, bool record) {
  const unsigned parts = asked_parts(args.partition);
  if (parts == 0) {
    if (record || !partition_refusal(mesh, options).empty()) return 1;
    return automatic_parts(mesh.face_count());
  }
  if (parts == 1) return 1;
  if (record)
    throw Error("--partition " + args.partition +
                " cannot be combined with --record: the parts' contractions are not one sequence to replay");
  if (const std::string why = partition_refusal(mesh, options); !why.empty())
    throw Error("--partition " + args.partition + ": cannot simplify part by part: " + why);
  return unsigned(parts);
}

SimplifyResult run_partitioned(MeshView mesh, const SimplifyOptions& options, unsigned parts, bool show_progress,
                               PartitionReport* report) {
  PartitionOptions partition;
  partition.parts = parts;
  if (show_progress)
    partition.progress = [](unsigned done, unsigned total) {
      std::fprintf(stderr, "\rqem: simplifying part by part: %u of %u parts done", done, total);
      std::fflush(stderr);
      return true;
    };
  SimplifyResult r = simplify_partitioned(mesh, options, partition, report);
  if (show_progress) std::fprintf(stderr, "\n");
  return r;
}

}  // namespace qem::cli
