// qem-mpi: the partitioned run of qem/partition.h across MPI ranks (Debian's OpenMPI), started
// with mpirun. Rank 0 reads the mesh, cuts it into parts (split_mesh) and sends part p to rank
// p mod ranks; every rank simplifies its parts (simplify_part, side by side on its threads) and
// sends the results back; rank 0 welds them, runs the final pass (finish_partitioned) and writes.
// Every rank parses the same command line, so the options need no message of their own: only the
// parts' arrays travel (MPI_Send / MPI_Recv). The parts and their results do not depend on where
// they were simplified, so the output is the same bytes as `qem simplify --partition P` on one
// machine with the same number of parts.
//
//   mpirun -np 4 qem-mpi IN.ply OUT.ply --ratio 0.1 [--parts P] [the options of qem simplify]
#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <optional>
#include <span>
#include <thread>
#include <vector>

#include "algorithm_options.h"
#include "cli_util.h"
#include "huge_pages.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/partition.h"
#include "qem/simplify.h"

namespace {

using namespace qem;

constexpr int kPartTag = 1, kResultTag = 2;

// Arrays travel as bytes in pieces of at most 1 GB (MPI counts are int).
template <class T>
void send_array(const std::vector<T>& v, int to, int tag) {
  const std::uint64_t n = v.size();
  MPI_Send(&n, 1, MPI_UINT64_T, to, tag, MPI_COMM_WORLD);
  const char* bytes = reinterpret_cast<const char*>(v.data());
  constexpr std::uint64_t kPiece = std::uint64_t(1) << 30;
  for (std::uint64_t at = 0, total = n * sizeof(T); at < total; at += kPiece)
    MPI_Send(bytes + at, int(std::min(kPiece, total - at)), MPI_BYTE, to, tag, MPI_COMM_WORLD);
}

template <class T>
void receive_array(std::vector<T>& v, int from, int tag) {
  std::uint64_t n = 0;
  MPI_Recv(&n, 1, MPI_UINT64_T, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  v.resize(n);
  char* bytes = reinterpret_cast<char*>(v.data());
  constexpr std::uint64_t kPiece = std::uint64_t(1) << 30;
  for (std::uint64_t at = 0, total = n * sizeof(T); at < total; at += kPiece)
    MPI_Recv(bytes + at, int(std::min(kPiece, total - at)), MPI_BYTE, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

// What simplify_part needs of a part: its mesh, locks and targets (the input numbering stays on rank 0).
void send_part(const MeshPart& p, int to) {
  send_array(p.mesh.positions, to, kPartTag);
  send_array(p.mesh.indices, to, kPartTag);
  send_array(p.locked, to, kPartTag);
  send_array(std::vector<std::uint64_t>{p.target_faces, p.target_vertices}, to, kPartTag);
}

MeshPart receive_part(int from) {
  MeshPart p;
  receive_array(p.mesh.positions, from, kPartTag);
  receive_array(p.mesh.indices, from, kPartTag);
  receive_array(p.locked, from, kPartTag);
  std::vector<std::uint64_t> targets;
  receive_array(targets, from, kPartTag);
  p.target_faces = targets.at(0), p.target_vertices = targets.at(1);
  return p;
}

void send_result(const MeshPartResult& r, int to) {
  send_array(r.mesh.positions, to, kResultTag);
  send_array(r.mesh.indices, to, kResultTag);
  send_array(r.vertex_source, to, kResultTag);
  send_array(r.face_source, to, kResultTag);
  send_array(r.output_vertex_of_input, to, kResultTag);
  send_array(std::vector<std::uint64_t>{r.input_faces, r.contractions, r.rejected_topology, r.rejected_inversion,
                                        r.rejected_error, r.rejected_component, r.dropped_duplicate_faces},
             to, kResultTag);
  send_array(std::vector<double>{r.max_error}, to, kResultTag);
}

MeshPartResult receive_result(int from) {
  MeshPartResult r;
  receive_array(r.mesh.positions, from, kResultTag);
  receive_array(r.mesh.indices, from, kResultTag);
  receive_array(r.vertex_source, from, kResultTag);
  receive_array(r.face_source, from, kResultTag);
  receive_array(r.output_vertex_of_input, from, kResultTag);
  std::vector<std::uint64_t> counts;
  receive_array(counts, from, kResultTag);
  std::vector<double> error;
  receive_array(error, from, kResultTag);
  r.input_faces = counts.at(0), r.contractions = counts.at(1), r.rejected_topology = counts.at(2);
  r.rejected_inversion = counts.at(3), r.rejected_error = counts.at(4), r.rejected_component = counts.at(5);
  r.dropped_duplicate_faces = counts.at(6);
  r.max_error = error.at(0);
  return r;
}

// This rank's parts (p mod ranks == rank), side by side on `threads` threads, one part per thread.
std::vector<MeshPartResult> simplify_parts(const std::vector<const MeshPart*>& parts, const SimplifyOptions& options) {
  SimplifyOptions one = options;
  one.threads = 1;
  std::vector<MeshPartResult> results(parts.size());
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  auto work = [&] {
    try {
      for (std::size_t i; (i = next++) < parts.size();) results[i] = simplify_part(*parts[i], one);
    } catch (...) {
      failure = std::current_exception();
      next = parts.size();
    }
  };
  const unsigned threads = options.threads > 0 ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < std::min<std::size_t>(threads, parts.size()); ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
  return results;
}

struct Args {
  std::string input, output;
  std::optional<std::size_t> faces, vertices;
  std::optional<double> ratio;
  unsigned parts = 0;
  bool json = false, quiet = false, ascii = false, force = false;
  cli::AlgorithmArgs algorithm;
};

SimplifyOptions options_of(const Args& a) {
  SimplifyOptions o = cli::to_simplify_options(a.algorithm);
  o.target_faces = a.faces.value_or(0);
  o.target_ratio = a.ratio.value_or(0);
  o.target_vertices = a.vertices.value_or(0);
  check_options(o);
  return o;
}

// Rank 0: read, cut, send, simplify its own parts, receive, finish, write.
int run_root(const Args& a, int ranks) {
  cli::Stopwatch total;
  unsigned parts = 0;  // told to the other ranks; 0 = stop (an error on rank 0)
  SimplifyResult r;
  PartitionReport report;
  try {
    cli::refuse_to_overwrite(a.input, a.output, a.force);
    SimplifyOptions options = options_of(a);
    Mesh mesh = cli::load_input(a.input, cli::to_load_options(a.algorithm));
    // --lock-property: the locks travel inside the parts (MeshPart::locked), so only rank 0 reads them.
    std::vector<std::uint8_t> lock;
    cli::apply_lock_property(a.algorithm, a.input, mesh, lock, options);
    if (const std::string why = partition_refusal(mesh, options); !why.empty())
      throw Error(a.input + ": cannot simplify part by part: " + why);
    // The parts go to the ranks as positions, faces and locks (send_part), which is all a mesh
    // without attributes needs; the threaded run (qem simplify --partition) carries them.
    if (!mesh.attributes.empty() || !mesh.face_materials.empty())
      throw Error(a.input + ": qem-mpi sends the parts' positions and faces only, and this mesh has " +
                  (mesh.attributes.empty() ? std::string("face materials") : "attributes (" + mesh.attributes.front().name + ", ...)") +
                  "; simplify it with qem simplify --partition, or without them");
    // At least one part per rank, so that every rank has work.
    parts = a.parts > 0 ? a.parts : std::max(automatic_parts(mesh.face_count()), unsigned(ranks));
    MPI_Bcast(&parts, 1, MPI_UNSIGNED, 0, MPI_COMM_WORLD);
    PartitionOptions partition;
    partition.parts = parts;
    partition.run_parts = [ranks](std::span<const MeshPart> all, const SimplifyOptions& o,
                                  std::span<MeshPartResult> results) {
      std::vector<const MeshPart*> mine;
      for (std::size_t p = 0; p < all.size(); ++p)
        if (p % std::size_t(ranks) == 0) mine.push_back(&all[p]);
        else send_part(all[p], int(p % std::size_t(ranks)));
      std::vector<MeshPartResult> own = simplify_parts(mine, o);
      for (std::size_t p = 0, k = 0; p < all.size(); ++p)
        results[p] = p % std::size_t(ranks) == 0 ? std::move(own[k++]) : receive_result(int(p % std::size_t(ranks)));
    };
    r = simplify_partitioned(mesh, options, partition, &report);
    SaveOptions save;
    save.binary = !a.ascii;
    save_mesh(a.output, r.mesh, save);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "qem-mpi: error: %s\n", e.what());
    if (parts == 0) MPI_Bcast(&parts, 1, MPI_UNSIGNED, 0, MPI_COMM_WORLD);  // the others stop
    else MPI_Abort(MPI_COMM_WORLD, 1);  // they are inside the exchange
    return 1;
  }
  if (a.json)
    std::printf(
        "{\"tool\":\"qem-mpi\",\"ranks\":%d,\"parts\":%u,\"in_faces\":%zu,\"out_faces\":%zu,\"out_vertices\":%zu,"
        "\"shared_vertices\":%zu,\"merged_faces\":%zu,\"split_s\":%s,\"parts_s\":%s,\"final_s\":%s,\"total_s\":%s,"
        "\"peak_rss_mb\":%s,\"max_error\":%s,\"stop\":\"%s\"}\n",
        ranks, report.parts, r.input_faces, r.mesh.face_count(), r.mesh.vertex_count(), report.shared_vertices,
        report.merged_faces, cli::json_number(report.split_seconds).c_str(),
        cli::json_number(report.parts_seconds).c_str(), cli::json_number(report.final_seconds).c_str(),
        cli::json_number(total.seconds()).c_str(), cli::json_number(cli::peak_rss_mb()).c_str(),
        cli::json_number(r.max_error).c_str(), to_string(r.stop_reason));
  if (!a.quiet)
    std::fprintf(stderr, "qem-mpi: %zu -> %zu faces in %u parts on %d ranks, %.3f s; %s\n", r.input_faces,
                 r.mesh.face_count(), report.parts, ranks, total.seconds(), r.stop_detail.c_str());
  return 0;
}

// Other ranks: receive their parts, simplify them, send the results back.
int run_worker(const Args& a, int rank, int ranks) {
  unsigned parts = 0;
  MPI_Bcast(&parts, 1, MPI_UNSIGNED, 0, MPI_COMM_WORLD);
  if (parts == 0) return 1;  // rank 0 said why
  try {
    const SimplifyOptions options = options_of(a);
    std::vector<MeshPart> mine;
    for (unsigned p = unsigned(rank); p < parts; p += unsigned(ranks)) mine.push_back(receive_part(0));
    std::vector<const MeshPart*> pointers;
    for (const MeshPart& p : mine) pointers.push_back(&p);
    for (const MeshPartResult& r : simplify_parts(pointers, options)) send_result(r, 0);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "qem-mpi: rank %d: error: %s\n", rank, e.what());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  qem::cli::with_malloc_tunables(argv);  // before MPI starts anything (cli/huge_pages.h)
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  CLI::App app{
      "qem-mpi: qem simplify's partitioned run across MPI ranks (docs/parallel.md). Start it with mpirun, e.g. "
      "mpirun -np 4 qem-mpi in.ply out.ply --ratio 0.1"};
  Args a;
  app.add_option("input", a.input, "Input mesh (.obj .ply .stl .off), read by rank 0")->required();
  app.add_option("output", a.output, "Output mesh, written by rank 0")->required();
  auto* g = app.add_option_group("target", "The target, shared among the parts");
  g->add_option("--faces,-f", a.faces, "Stop at this many faces");
  g->add_option("--ratio,-r", a.ratio, "Stop at this fraction of the input faces");
  g->add_option("--vertices", a.vertices, "Stop at this many vertices");
  g->require_option(1, 3);
  app.add_option("--parts", a.parts,
                 "Number of parts (default: as qem simplify --partition auto, at least one per rank); part p goes "
                 "to rank p mod ranks. The output depends on it, not on the ranks or threads");
  cli::add_algorithm_options(&app, a.algorithm);
  app.add_flag("--json", a.json, "Print one JSON line (rank 0) with counts, parts and timings");
  app.add_flag("--quiet,-q", a.quiet, "No summary on stderr");
  app.add_flag("--ascii", a.ascii, "Write PLY / STL as text");
  app.add_flag("--force", a.force, "Allow the output to overwrite the input file");
  int code = 0;
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    code = rank == 0 ? app.exit(e) : (e.get_exit_code() == 0 ? 0 : 1);
    MPI_Finalize();
    return code;
  }
  code = rank == 0 ? run_root(a, ranks) : run_worker(a, rank, ranks);
  MPI_Finalize();
  return code;
}
