#include "out_of_core_cli.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "cli_util.h"
#include "partition_cli.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/out_of_core.h"

namespace qem::cli {

void add_out_of_core_options(CLI::App* sub, OutOfCoreArgs& args) {
  sub->add_option("--memory-limit", args.memory_limit,
                  "Memory budget, e.g. 2G or 512M (default: half of the available memory). A binary PLY or "
                  "STL whose in-memory run would exceed it is simplified out of core: clustered while "
                  "streamed (Lindstrom 2000), then simplified in memory; or, when it is within a few budgets "
                  "and the budget would leave that second phase too few faces, part by part on disk "
                  "(docs/out-of-core.md)");
  sub->add_option("--temp-dir", args.temp_dir,
                  "Folder for the out-of-core run's temporary files (default: $TMPDIR, else the output's "
                  "folder); they are removed at the end, on failure and on Ctrl-C");
  sub->add_option("--phase2-size", args.phase2_size,
                  "Out of core: the clustered mesh handed to the in-memory pass has at most about this many "
                  "times the target's faces (fewer when the memory limit says so); larger is slower and "
                  "closer to an in-memory run; 0 = as many as the memory limit allows")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
}

bool wants_out_of_core(const std::string& input, const OutOfCoreArgs& args) {
  const std::uint64_t limit = args.memory_limit.empty() ? 0 : parse_memory_size(args.memory_limit);
  return !fits_in_memory(input, limit);
}

int run_out_of_core(const std::string& input, const std::string& output, const SimplifyOptions& options,
                    const OutOfCoreArgs& args, const OutputArgs& out) {
  OutOfCoreOptions ooc;
  if (!args.memory_limit.empty()) ooc.memory_limit = parse_memory_size(args.memory_limit);
  ooc.temp_dir = args.temp_dir;
  ooc.phase2_faces_per_target = args.phase2_size;
  ooc.parts = asked_parts(args.partition);  // 0 = automatic
  if (ooc.temp_dir.empty() && !std::getenv("TMPDIR")) {
    const auto slash = output.find_last_of('/');
    ooc.temp_dir = slash == std::string::npos ? "." : output.substr(0, slash + 1);
  }
  const bool show = !out.quiet && !out.json;
  const bool tty = ::isatty(STDERR_FILENO);
  if (show)
    ooc.progress = [tty](const OutOfCoreProgress& p) {
      char left[32] = "";
      if (p.seconds_left >= 0) std::snprintf(left, sizeof left, ", about %.0f s left", p.seconds_left);
      std::fprintf(stderr, "%sqem: out of core, phase %d/%d %s: %.2f of %.2f GB read, %.0f s%s%s",
                   tty ? "\r" : "", p.phase_index, p.phase_count, p.phase, double(p.bytes_read) / 1e9,
                   double(p.bytes_total) / 1e9, p.seconds, left, tty ? "\x1b[K" : "\n");
      std::fflush(stderr);
      return true;
    };
  Stopwatch total;
  OutOfCoreReport report;
  SimplifyResult r = simplify_out_of_core(input, options, ooc, &report);
  if (show && tty) std::fprintf(stderr, "\n");
  if (!report.unread.empty() && !out.quiet) {  // nothing dropped without a word
    std::string names;
    for (const std::string& n : report.unread) names += (names.empty() ? "" : ", ") + n;
    std::fprintf(stderr, "qem: note: %s: out of core keeps positions and faces only; not carried: %s\n",
                 input.c_str(), names.c_str());
  }
  if (report.memory_needed > 0 && !out.quiet)  // the target wins over the limit, with a word
    std::fprintf(
        stderr,
        "qem: note: %s: --memory-limit %.3g MB is below what the target (%zu faces) needs out of core, "
        "about %.3g MB; the run took what it needed (peak %.3g MB) rather than end below the target\n",
        input.c_str(), double(report.memory_limit) / 1e6, report.target_faces,
        double(report.memory_needed) / 1e6, double(report.peak_memory_bytes) / 1e6);
  SaveOptions save;
  save.binary = !out.ascii;
  save.double_precision = out.double_values;
  save_mesh(output, r.mesh, save);
  if (out.json) {
    std::string phases = "[";
    for (const OutOfCorePhase& p : report.phases)
      phases += std::string(phases.size() > 1 ? "," : "") + "{\"name\":" + json_string(p.name) +
                ",\"seconds\":" + json_number(p.seconds) + ",\"cpu_seconds\":" + json_number(p.cpu_seconds) +
                "}";
    phases += "]";
    std::string unread = "[";
    for (const std::string& n : report.unread)
      unread += std::string(unread.size() > 1 ? "," : "") + json_string(n);
    unread += "]";
    std::printf(
        // clang-format off (one group of fields a line, no name split)
        "{\"tool\":\"qem\",\"out_of_core\":true,\"method\":%s,\"in_faces\":%llu,\"target_faces\":%zu,"
        "\"out_faces\":%zu,\"out_vertices\":%zu,\"clustered_faces\":%llu,\"merged_faces\":%llu,"
        "\"shared_vertices\":%llu,\"grid_resolution\":%llu,\"grid_coarsenings\":%u,\"grid_refinements\":%u,"
        "\"topology_relaxed\":%s,\"memory_limit_bytes\":%llu,\"peak_memory_bytes\":%llu,"
        "\"memory_needed_bytes\":%llu,\"temp_bytes_written\":%llu,\"parts\":%u,\"total_s\":%s,\"cpu_s\":%s,"
        "\"peak_rss_mb\":%s,\"max_error\":%s,\"max_error_rel\":%s,\"stop\":\"%s\",\"phases\":%s,"
        "\"not_carried\":%s}\n",
        // clang-format on
        json_string(report.method).c_str(), static_cast<unsigned long long>(report.input_faces),
        report.target_faces, r.mesh.face_count(), r.mesh.vertex_count(),
        static_cast<unsigned long long>(report.clustered_faces),
        static_cast<unsigned long long>(report.merged_faces),
        static_cast<unsigned long long>(report.shared_vertices),
        static_cast<unsigned long long>(report.grid_resolution), report.grid_coarsenings,
        report.grid_refinements, report.topology_relaxed ? "true" : "false",
        static_cast<unsigned long long>(report.memory_limit),
        static_cast<unsigned long long>(report.peak_memory_bytes),
        static_cast<unsigned long long>(report.memory_needed),
        static_cast<unsigned long long>(report.temp_bytes_written), report.parts,
        json_number(total.seconds()).c_str(), json_number(process_cpu_seconds()).c_str(),
        json_number(peak_rss_mb()).c_str(), json_number(r.max_error).c_str(),
        json_number(r.max_error_relative).c_str(), to_string(r.stop_reason), phases.c_str(), unread.c_str());
  }
  if (!out.quiet && report.method == "parts")
    std::fprintf(
        stderr,
        "qem: %llu -> %zu faces out of core (by %u parts on disk, %llu vertices on their cuts, welded "
        "to %llu faces), %.3f s, peak memory %.0f MB, %.0f MB of temporary files\n",
        static_cast<unsigned long long>(report.input_faces), r.mesh.face_count(), report.parts,
        static_cast<unsigned long long>(report.shared_vertices),
        static_cast<unsigned long long>(report.merged_faces), total.seconds(),
        double(report.peak_memory_bytes) / 1e6, double(report.temp_bytes_written) / 1e6);
  else if (!out.quiet)
    std::fprintf(
        stderr,
        "qem: %llu -> %zu faces out of core (clustered to %llu faces on a grid of %llu, %u parts), %.3f s, "
        "peak memory %.0f MB, %.0f MB of temporary files\n",
        static_cast<unsigned long long>(report.input_faces), r.mesh.face_count(),
        static_cast<unsigned long long>(report.clustered_faces),
        static_cast<unsigned long long>(report.grid_resolution), report.parts, total.seconds(),
        double(report.peak_memory_bytes) / 1e6, double(report.temp_bytes_written) / 1e6);
  return 0;
}

}  // namespace qem::cli
