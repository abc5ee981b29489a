// Garland & Shaffer 2002's two phases: Lindstrom 2000 out-of-core clustering
// (outofcore/parallel_clustering.h, the grid sized here from a sample), then GH97 in core
// (qem::simplify, or part by part) on the clustered mesh.
#include "qem/out_of_core.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

#include "cluster/cluster_quadric.h"
#include "core/quadric.h"
#include "core/release_memory.h"
#include "geometry/vec3.h"
#include "outofcore/cell_table.h"
#include "outofcore/mesh_stream.h"
#include "outofcore/parallel_clustering.h"
#include "outofcore/streamed_parts.h"
#include "outofcore/temp_file.h"
#include "qem/error.h"
#include "qem/mesh_info.h"
#include "qem/partition.h"
#include "refit/refit_after_simplify.h"
#include "refit/refit_points.h"

namespace qem {
namespace {

using outofcore::CellKey;
using outofcore::CellSet;
using outofcore::CellTable;
using outofcore::Grid;
using outofcore::kInCoreBytesPerFace;
using outofcore::MeshStream;
using outofcore::ParallelClustering;
using outofcore::PositionSource;
using outofcore::TempFile;

/// Phase 1 per occupied cell: its quadric, corner sum and edge sums (21 doubles) and its hash
/// slot (at most half full). Phase 2 per cell: about 1.6 faces (measured on the spheres), each taking the
/// in-core path's bytes plus the clustered mesh handed to it and the pairing of its faces; 2 GB
/// held 8 million clustered faces at 1.99 GB peak with 2 faces a cell and 180 bytes a face, hence
/// the margin.
constexpr double kClusterBytesPerCell = 208;
constexpr double kPhase2BytesPerCell = 520;
/// The finest grid: 2^20 cells along the longest side (keys hold 21 bits an axis).
constexpr double kFinestResolution = double(1 << 20);
/// Refinements of a grid found too coarse after the clustering (simplify_out_of_core), each while
/// its faces grow by at least kRegridGrowth.
constexpr std::uint64_t kMaxRegrids = 3;
constexpr double kRegridGrowth = 1.2;

std::uint64_t peak_rss_bytes() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::strtoull(line.c_str() + 6, nullptr, 10) * 1024;
  return 0;
}

double process_cpu_seconds() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

std::string default_temp_dir() {
  if (const char* t = std::getenv("TMPDIR"); t && *t) return t;
  return "/tmp";
}

/// Progress of the reading passes: bytes read against the bytes all passes will read.
class Progress {
 public:
  Progress(const OutOfCoreOptions& o, int phases) : options_(o), phases_(phases) {}
  void phase(const char* name, int index) {
    p_.phase = name;
    p_.phase_index = index;
    report(true);
  }
  void set_total(std::uint64_t bytes) { p_.bytes_total = bytes; }
  /// One more pass over `bytes` of the file (a refined grid), counted after what was read: read()
  /// takes that pass's own count from then on.
  void add_pass(std::uint64_t bytes) {
    base_ = p_.bytes_total;
    p_.bytes_total += bytes;
  }
  void read(std::uint64_t bytes_read) {
    // A pass may read a buffer's worth past its element: the total counts each byte once.
    p_.bytes_read = std::min(base_ + bytes_read, p_.bytes_total);
    report(false);
  }
  /// Phase 2: the simplifier's fraction done.
  void fraction(double f) {
    const double t = seconds();
    if (f > 0.01) p_.seconds_left = (t - phase2_start_) * (1 - f) / f;
    report(false);
  }
  void start_phase2() { phase2_start_ = seconds(); }
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  void report(bool force) {
    const double t = seconds();
    if (!force && t - last_ < 1.0) return;
    last_ = t;
    p_.seconds = t;
    p_.phase_count = phases_;
    if (p_.bytes_total > 0 && p_.bytes_read > 0 && p_.bytes_read < p_.bytes_total && p_.phase_index < phases_)
      p_.seconds_left = t * double(p_.bytes_total - p_.bytes_read) / double(p_.bytes_read);
    if (options_.progress && !options_.progress(p_)) throw Error("cancelled");
  }

  const OutOfCoreOptions& options_;
  int phases_;
  OutOfCoreProgress p_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  double last_ = -1, phase2_start_ = 0;
  std::uint64_t base_ = 0;
};

/// Forwards the in-core simplifier's progress.
class Phase2Observer : public SimplifyObserver {
 public:
  explicit Phase2Observer(Progress& p) : progress_(p) {}
  bool on_progress(double f) override {
    progress_.fraction(f);
    return true;
  }

 private:
  Progress& progress_;
};

/// The input's positions, for the clustering pass's random access. Mapped from the input itself
/// when its vertex rows hold float x, y, z (nothing copied); otherwise kept as float (12 bytes a
/// vertex) in memory when they take at most a third of the budget, else in a temporary file mapped
/// read-only. Mapped pages belong to the kernel's page cache: drop_pages() takes them out of the
/// process (they stay cached and come back on the next touch), so that the resident set keeps to
/// the budget however large the input.
class PositionStore {
 public:
  /// The `count` rows of `row` bytes at `offset` in `path`, x, y, z as float at `at`.
  PositionStore(const std::string& path, std::uint64_t offset, std::size_t row, const std::size_t at[3],
                std::uint64_t count)
      : count_(count) {
    source_.row = row;
    std::copy(at, at + 3, source_.at);
    map(path, offset, count * row);
  }
  /// Positions appended as read, in memory or in a temporary file in `temp_dir`.
  PositionStore(std::uint64_t vertices, bool in_memory, const std::string& temp_dir) : count_(vertices) {
    if (in_memory) {
      memory_.reserve(3 * vertices);
    } else {
      file_ = std::make_unique<TempFile>(temp_dir, "positions");
    }
    copied_ = true;
  }
  ~PositionStore() { unmap(); }
  bool copied() const { return copied_; }
  void append(const double* xyz, std::size_t n) {
    for (std::size_t i = 0; i < 3 * n; ++i) {
      const float f = static_cast<float>(xyz[i]);
      if (file_)
        file_->put(f);
      else
        memory_.push_back(f);
    }
  }
  /// After the last append: where the positions are.
  const PositionSource& finish() {
    if (file_) {
      file_->flush();
      map(file_->path(), 0, count_ * 12);
    } else if (copied_) {
      source_.base = reinterpret_cast<const unsigned char*>(memory_.data());
    }
    return source_;
  }
  bool mapped() const { return map_ != nullptr; }
  void drop_pages() {
    if (map_) ::madvise(map_, map_bytes_, MADV_DONTNEED);
  }
  void release() {
    unmap();
    std::vector<float>().swap(memory_);
    file_.reset();
  }

 private:
  void map(const std::string& path, std::uint64_t offset, std::uint64_t bytes) {
    if (bytes == 0) return;
    const std::uint64_t page = std::uint64_t(::sysconf(_SC_PAGESIZE));
    const std::uint64_t start = offset / page * page;
    map_bytes_ = std::size_t(offset - start + bytes);
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw Error(path + ": cannot reopen: " + std::strerror(errno));
    map_ = ::mmap(nullptr, map_bytes_, PROT_READ, MAP_SHARED, fd, off_t(start));
    ::close(fd);
    if (map_ == MAP_FAILED) {
      map_ = nullptr;
      throw Error(path + ": cannot map: " + std::strerror(errno));
    }
    source_.base = static_cast<const unsigned char*>(map_) + (offset - start);
  }
  void unmap() {
    if (map_) ::munmap(map_, map_bytes_);
    map_ = nullptr;
  }

  std::uint64_t count_;
  bool copied_ = false;
  PositionSource source_;
  std::vector<float> memory_;
  std::unique_ptr<TempFile> file_;
  void* map_ = nullptr;
  std::size_t map_bytes_ = 0;
};

/// Resident pages of the process that are mapped from files (its code, the mapped positions), from
/// /proc/self/statm: those drop_pages() gives back.
std::uint64_t resident_file_bytes() {
  std::ifstream in("/proc/self/statm");
  std::uint64_t size = 0, resident = 0, shared = 0;
  in >> size >> resident >> shared;
  return shared * std::uint64_t(::sysconf(_SC_PAGESIZE));
}

/// The cell size the clustering starts from. A sample of the points counts the occupied cells at
/// coarse grids, where each cell holds many samples and the count is close to the input's; a
/// surface's count grows with the square of the resolution, which extrapolates it to `goal_cells`.
/// A surface rougher than the sample shows gives more cells: the clustering then coarsens its grid
/// (ParallelClustering), so an estimate too fine costs a coarsening, never memory.
double starting_cell_size(const std::vector<float>& sample, const double lo[3], double extent,
                          std::uint64_t goal_cells) {
  const std::size_t n = sample.size() / 3;
  double resolution = 1, cells = 1;
  for (double r = 2; r <= kFinestResolution; r *= 2) {
    CellSet set(n);
    const Grid g{{lo[0], lo[1], lo[2]}, extent / r};
    for (std::size_t i = 0; i < n; ++i)
      set.insert(g.key(sample[3 * i], sample[3 * i + 1], sample[3 * i + 2]));
    if (double(set.size()) > double(n) / 16) break;  // too few samples a cell to count them all
    resolution = r, cells = double(set.size());
  }
  const double estimate = resolution * std::sqrt(double(goal_cells) / cells);
  return extent / std::min(kFinestResolution, estimate);
}

/// The cell's quadric, plus, where the input's border crosses the cell, the squared distance to the
/// border's line (GH97 §4's border planes, in the form a stream allows). The interior edges
/// cancelled in the cell's edge sums; what remains, D = sum(b - a) and M = sum(a x b) over the
/// border's edges, gives the line through (D x M) / |D|^2 along D (exact for a straight border).
/// Without it a border cell's quadric is flat across the border and its vertex keeps the corners'
/// mean, up to a cell inside: the clustered border shrank by up to a cell, the output's farthest
/// points from the input on an open surface. Weighted by the quadric's trace (its faces' area),
/// as strong as the surface's own planes. A border shorter than a quarter of the cell (or sums
/// left by rounding) adds nothing.
core::Quadric with_border(const outofcore::CellSums& cell, double cell_size) {
  core::Quadric q = cell.quadric;
  const Vec3 D{cell.edge[0], cell.edge[1], cell.edge[2]}, M{cell.moment[0], cell.moment[1], cell.moment[2]};
  const double dd = dot(D, D);
  if (!(dd > 0.0625 * cell_size * cell_size)) return q;
  const Vec3 d = D / std::sqrt(dd), c = cross(D, M) / dd;
  const double w = q.a00 + q.a11 + q.a22;
  // w (|x - c|^2 - ((x - c).d)^2) = x^T A x + 2 b.x + c0 with A = w (I - d d^T), b = -A c.
  core::Quadric line;
  line.a00 = w * (1 - d.x * d.x), line.a01 = -w * d.x * d.y, line.a02 = -w * d.x * d.z;
  line.a11 = w * (1 - d.y * d.y), line.a12 = -w * d.y * d.z, line.a22 = w * (1 - d.z * d.z);
  const Vec3 ac = line.apply_a(c);
  line.b0 = -ac.x, line.b1 = -ac.y, line.b2 = -ac.z;
  line.c = dot(c, ac);
  q += line;
  return q;
}

/// Keeps a cell's representative `x` (the minimum of its quadric `q`) inside the cell [c0, c1].
/// Two candidates, the one of lower error under `q` kept: `x` clamped coordinate by coordinate,
/// and the point where the segment from the corners' `mean` (inside the cell, on the surface up to
/// its roughness) to `x` (on the quadric's best-fitting planes) leaves the cell. Clamping alone
/// moves the point along the axes, off any surface oblique to them by up to a cell's size: on a
/// noisy scan, where the noise gives every cell's quadric full rank and puts a few per cent of the
/// minima outside their cells, such points were the farthest of the output from the input
/// (Hausdorff 2.2x the in-core run's on the jittered 1.3M sphere at 10 %, docs/out-of-core.md).
/// The segment alone moves a border cell's point off the border when its minimum leaves the cell
/// across another wall, the mean lying inside the border; there clamping is the better.
void pull_into_cell(const core::Quadric& q, const double mean[3], const double c0[3], const double c1[3],
                    double x[3]) {
  // A non-finite minimum (not expected from the truncated pseudo-inverse) keeps the mean.
  if (!std::isfinite(x[0] + x[1] + x[2])) std::copy(mean, mean + 3, x);
  double t = 1;  // the fraction of the segment mean -> x kept
  for (int a = 0; a < 3; ++a) {
    const double d = x[a] - mean[a];
    if (x[a] > c1[a] && d > 0) t = std::min(t, (c1[a] - mean[a]) / d);
    if (x[a] < c0[a] && d < 0) t = std::min(t, (c0[a] - mean[a]) / d);
  }
  if (t >= 1) return;  // inside
  t = std::max(t, 0.0);
  // The final clamps only catch rounding (and a mean a rounding outside its cell).
  double pulled[3], clamped[3];
  for (int a = 0; a < 3; ++a) {
    pulled[a] = std::clamp(mean[a] + t * (x[a] - mean[a]), c0[a], c1[a]);
    clamped[a] = std::clamp(x[a], c0[a], c1[a]);
  }
  const auto error = [&](const double* p) { return q.evaluate(Vec3{p[0], p[1], p[2]}); };
  std::copy_n(error(clamped) < error(pulled) ? clamped : pulled, 3, x);
}

/// Phase 2 can stop above the target where the clustering folded thin parts onto each other (a CAD
/// part's walls thinner than a cell, parts closer than a cell: edges of three or four faces, which
/// the link condition refuses to contract and the exact borders hold), though an in-core run of the
/// same input reaches it (the cycloidal gear to 10 % under 2 MB: 7,310 faces of 4,336). From there
/// it goes on under GH97's own rules, which let a contraction make a non-manifold edge, with
/// penalty planes at the borders; kept only where it opens no boundary edge. True if kept.
/// `observer` forwards its progress (and a cancel).
bool past_the_folds(SimplifyResult& r, const SimplifyOptions& phase2, SimplifyObserver* observer) {
  const bool above = (phase2.target_faces && r.mesh.face_count() > phase2.target_faces) ||
                     (phase2.target_vertices && r.mesh.vertex_count() > phase2.target_vertices);
  if (r.stop_reason != StopReason::NoValidPair || !above) return false;
  SimplifyOptions o = phase2;
  o.preserve_topology = false;
  o.exact_border = false;
  o.refit_rounds = 0;  // the refit against the input follows
  o.far_repair = false;
  SimplifyResult more = simplify(r.mesh, o, observer);
  if (more.contractions == 0 || mesh_info(more.mesh).boundary_edges > mesh_info(r.mesh).boundary_edges)
    return false;
  // The provenance through both runs.
  if (!r.face_source.empty())
    for (std::uint32_t& f : more.face_source) f = r.face_source[f];
  if (!r.vertex_source.empty())
    for (std::uint32_t& v : more.vertex_source) v = r.vertex_source[v];
  more.contractions += r.contractions;
  more.max_error = std::max(more.max_error, r.max_error);
  more.max_error_relative = std::max(more.max_error_relative, r.max_error_relative);
  more.input_faces = r.input_faces, more.input_vertices = r.input_vertices;
  more.input_components = r.input_components;
  r = std::move(more);
  return true;
}

/// About `wanted` of the input's points (a PLY's vertices, an STL's corners) for the refit against
/// the input, memory following the output, not the input: each point kept with probability
/// wanted / total by a hash of its index (the same points on every run). Every k-th in file order
/// beat against the rows of a height field (every third column of the terrain's rows: the refit
/// then raised E), a hash does not. Each carries weight 1, the refit's area weights (a third of
/// each face's area a corner) being out of reach without a per-vertex table the size of the input:
/// on inputs whose vertices are spread evenly (scanners at their resolution, generated meshes,
/// height fields) equal weights are area weights up to a constant, which the fit does not see.
std::vector<double> input_points(const std::string& path, double wanted, std::uint64_t total) {
  MeshStream in(path);
  const double keep = std::min(1.0, wanted / double(std::max<std::uint64_t>(total, 1)));
  const auto threshold = std::uint64_t(std::ldexp(keep, 53));
  std::vector<double> points;
  std::uint64_t index = 0;
  auto take = [&](const double* xyz, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i, ++index) {
      // splitmix64's finaliser of the index: 53 uniform bits.
      std::uint64_t z = index + 0x9E3779B97F4A7C15ull;
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
      z ^= z >> 31;
      if (keep < 1 && (z >> 11) >= threshold) continue;
      // As float, the precision phase 1 kept the positions in.
      for (int a = 0; a < 3; ++a) points.push_back(static_cast<float>(xyz[3 * i + a]));
    }
  };
  if (in.indexed())
    in.read_vertices(take);
  else
    in.read_soup([&](const double* xyz, std::size_t n) { take(xyz, 3 * n); });
  return points;
}

/// The refit's memory (measured on the 2.9M terrain's output at 10 %, 287,519 faces, with 0.6M and
/// 1.15M points): about 200 bytes a point and 410 bytes an output face (the output included),
/// kept here with a margin; the program and its buffers come on top of the budget, as in the
/// phases before.
constexpr double kRefitBytesPerPoint = 240, kRefitBytesPerFace = 450;

/// How many of the input's points the refit after phase 2 fits the output to: its points per
/// output vertex (8 when it asks for every input vertex), as many as the budget holds, and none
/// when that leaves fewer than 2 a vertex (with 0.7 points a vertex the refit raised the terrain's
/// E by 26 %: it fits the few points and drags the rest).
std::size_t refit_points_within(const RefitOptions& refit, const Mesh& output, double budget) {
  const double per_vertex = refit.points_per_vertex > 0 ? refit.points_per_vertex : 8;
  const double vertices = double(output.vertex_count());
  const double room = budget - kRefitBytesPerFace * double(output.face_count());
  const double points = std::min(per_vertex * vertices, room / kRefitBytesPerPoint);
  return points >= 2 * vertices && vertices > 0 ? std::size_t(points) : 0;
}

}  // namespace

std::uint64_t default_memory_limit() {
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("MemAvailable:", 0) == 0) {
      const std::uint64_t avail = std::strtoull(line.c_str() + 13, nullptr, 10) * 1024;
      return std::max<std::uint64_t>(avail / 2, std::uint64_t(256) << 20);
    }
  return std::uint64_t(4) << 30;
}

std::uint64_t parse_memory_size(const std::string& text) {
  const auto bad = [&] {
    return Error("memory size '" + text +
                 "': expected a number of bytes with an optional K, M, G or T suffix");
  };
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (...) {
    throw bad();
  }
  std::string unit = text.substr(used);
  if (!unit.empty() && (unit.back() == 'B' || unit.back() == 'b')) unit.pop_back();
  double scale = 1;
  if (unit == "K" || unit == "k")
    scale = 1024.0;
  else if (unit == "M" || unit == "m")
    scale = 1024.0 * 1024;
  else if (unit == "G" || unit == "g")
    scale = 1024.0 * 1024 * 1024;
  else if (unit == "T" || unit == "t")
    scale = 1024.0 * 1024 * 1024 * 1024;
  else if (!unit.empty())
    throw bad();
  if (!(v > 0) || !std::isfinite(v * scale) || v * scale > 1e18) throw bad();
  return std::uint64_t(v * scale);
}

bool fits_in_memory(const std::string& path, std::uint64_t memory_limit) {
  if (!MeshStream::streamable_extension(path)) return true;
  const std::uint64_t limit = memory_limit ? memory_limit : default_memory_limit();
  std::uint64_t faces = 0, bytes = 0;
  try {
    MeshStream in(path);
    faces = in.face_count();
    bytes = in.file_size();
  } catch (const Error&) {
    return true;  // an ASCII file or a broken one: the in-memory reader reads it or says what is wrong
  }
  return double(bytes) + kInCoreBytesPerFace * double(faces) <= double(limit);
}

SimplifyResult simplify_out_of_core(const std::string& path, const SimplifyOptions& input_options,
                                    const OutOfCoreOptions& ooc, OutOfCoreReport* report_out) {
  if (!input_options.vertex_lock.empty())
    throw Error(
        "per-vertex locks are not supported out of core (the clustering merges the input's vertices)");
  // The bound is certified against the input's surface, which out of core is never in memory:
  // phase 2 sees only the clustered mesh, so it could not promise the distance to the input.
  if (std::isfinite(input_options.max_distance))
    throw Error(path + ": a distance bound (--max-distance) needs the whole input in memory, and this run is out "
                       "of core; raise --memory-limit so that it fits, or leave the bound out");
  OutOfCoreReport report;
  report.memory_limit = ooc.memory_limit ? ooc.memory_limit : default_memory_limit();
  const std::string temp_dir = ooc.temp_dir.empty() ? default_temp_dir() : ooc.temp_dir;
  const std::uint64_t temp_bytes_before = outofcore::temp_bytes_written();
  MeshStream in(path);
  report.input_faces = in.face_count();
  report.input_vertices = in.vertex_count();
  report.unread = in.unread();
  const bool soup = !in.indexed();
  // A ratio is of the input's faces, not of the clustered mesh phase 2 starts from.
  SimplifyOptions options = input_options;
  if (options.target_ratio > 0) {
    const auto by_ratio = std::size_t(std::floor(options.target_ratio * double(report.input_faces)));
    options.target_faces = options.target_faces ? std::min(options.target_faces, by_ratio) : by_ratio;
    options.target_ratio = 0;
  }
  report.target_faces = options.target_faces;
  Progress progress(ooc, 3);
  // The passes over the file: PLY once (vertices, then faces), STL twice (bounds, clusters).
  progress.set_total(soup ? 2 * in.file_size() : in.file_size());
  auto lap = [&, t = 0.0, cpu = process_cpu_seconds()](const char* name) mutable {
    const double now = progress.seconds(), cpu_now = process_cpu_seconds();
    report.phases.push_back({name, now - t, cpu_now - cpu});
    t = now, cpu = cpu_now;
  };

  // The budget: 90 % of the limit (the rest for the program itself and the read buffers).
  const double budget = 0.9 * double(report.memory_limit);
  const std::uint64_t nv = in.vertex_count();
  std::uint64_t layout_offset = 0;
  std::size_t layout_row = 0, layout_at[3] = {0, 0, 0};
  const bool map_input = !soup && in.float_vertex_layout(layout_offset, layout_row, layout_at);
  const bool positions_in_memory = !soup && !map_input && 12.0 * double(nv) <= budget / 3;

  const double phase1_room = budget - (positions_in_memory ? 12.0 * double(nv) : 0.0);
  std::uint64_t max_cells = std::uint64_t(
      std::max(0.0, std::min(phase1_room / kClusterBytesPerCell, budget / kPhase2BytesPerCell)));
  // Phase 2's time: the clustered mesh need not be larger than a multiple of the target (about
  // two faces a cell on a closed surface).
  const double target =
      options.target_faces ? double(options.target_faces) : 2.0 * double(options.target_vertices);
  const std::uint64_t goal_by_time = target > 0 && ooc.phase2_faces_per_target > 0
                                         ? std::uint64_t(ooc.phase2_faces_per_target * target / 2)
                                         : std::numeric_limits<std::uint64_t>::max();
  // Never fewer cells than the target's vertices, or phase 2 would have nothing to choose from.
  const std::uint64_t floor_cells =
      std::max<std::uint64_t>({options.target_faces, options.target_vertices * 2, 1024});
  // Whether the budget, not the time bound, sizes phase 2: then it gets fewer than the goal's
  // multiple of the target, and its result suffers (docs/out-of-core.md, "Why two phases").
  const bool budget_binds = max_cells < goal_by_time;
  // A budget below the floor: the target wins and the run takes more than the limit, which the
  // report says (with about the limit the floor needs).
  if (max_cells < floor_cells) {
    const double resident = positions_in_memory ? 12.0 * double(nv) : 0.0;
    const double needed = std::max(resident + double(floor_cells) * kClusterBytesPerCell,
                                   double(floor_cells) * kPhase2BytesPerCell);
    report.memory_needed = std::uint64_t(std::ceil(needed / 0.9));
  }
  max_cells = std::max(max_cells, floor_cells);
  // The grid aims at the goal; the clustering coarsens it when the cells pass twice the goal (the
  // time bound is soft) or the budget's (a hard bound).
  // When the budget binds, the grid aims at 75 % of it: an estimate a little short then still fits,
  // where a coarsening would leave a quarter of the cells (the sample's estimate came within
  // 0.87-1.2x of the cells on the spheres and tori of docs/benchmarks.md).
  // A coarsening leaves about a quarter of the cells (a surface's cells go with the square of the
  // resolution): the hard bound is at least twice the floor, so that one leaves at least half the
  // floor's cells, about the target's faces at two faces a cell (the fandisk, 12,946 faces, to 10 %
  // under 600 KB: a grid aimed at the floor's 1,294 cells passed it, was coarsened, and left 676
  // faces; now 2,664 and no coarsening).
  const std::uint64_t hard_cells = std::max(
      goal_by_time < max_cells / 2 ? std::max(2 * goal_by_time, floor_cells) : max_cells, 2 * floor_cells);
  const std::uint64_t goal_cells = std::max(
      goal_by_time < max_cells / 2 ? goal_by_time : std::uint64_t(0.75 * double(max_cells)), floor_cells);

  // --- pass 1: bounds (and, for a PLY, the positions) ---------------------------------------------
  progress.phase("bounds", 1);
  double lo[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                  std::numeric_limits<double>::infinity()};
  double hi[3] = {-lo[0], -lo[1], -lo[2]};
  // Every sample_step-th point, up to a million, for starting_cell_size.
  const std::uint64_t points = soup ? 3 * report.input_faces : nv;
  // Within the budget: a sample point takes less than a cell.
  const std::uint64_t sample_step =
      std::max<std::uint64_t>(1, points / std::min<std::uint64_t>(1000000, max_cells));
  std::vector<float> sample;
  std::uint64_t until_sample = 0;
  auto grow = [&](const double* xyz, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      for (int a = 0; a < 3; ++a) {
        // As float, the precision the positions are kept in (and every cell is computed from).
        const double v = static_cast<float>(xyz[3 * i + a]);
        lo[a] = std::min(lo[a], v), hi[a] = std::max(hi[a], v);
      }
      if (until_sample-- == 0) {
        sample.insert(sample.end(), {float(xyz[3 * i]), float(xyz[3 * i + 1]), float(xyz[3 * i + 2])});
        until_sample = sample_step - 1;
      }
    }
    progress.read(in.bytes_read());
  };
  const auto new_store = [&] {
    return map_input ? std::make_unique<PositionStore>(path, layout_offset, layout_row, layout_at, nv)
                     : std::make_unique<PositionStore>(nv, positions_in_memory, temp_dir);
  };
  std::unique_ptr<PositionStore> store;
  if (soup) {
    in.read_soup([&](const double* xyz, std::size_t n) { grow(xyz, 3 * n); });
  } else {
    store = new_store();
    in.read_vertices([&](const double* xyz, std::size_t n) {
      if (store->copied()) store->append(xyz, n);
      grow(xyz, n);
    });
  }
  PositionSource positions = store ? store->finish() : PositionSource{};
  if (report.input_faces == 0 || !(lo[0] <= hi[0])) throw Error(path + ": no faces to simplify");
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-30});
  lap("bounds");

  // By parts (outofcore/streamed_parts.h) where the budget would starve phase 2 and the input is
  // within a few budgets: every face contracted, as the partitioned in-memory run does; else (and
  // when the parts find a two-sided sheet) the two phases.
  const unsigned threads =
      options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  // Mapped positions: their pages are given back whenever they pass a quarter of the budget.
  const std::uint64_t mapped_allowance =
      std::max<std::uint64_t>(std::uint64_t(budget / 4), std::uint64_t(32) << 20);
  const auto give_back_pages = [&] {
    if (store && store->mapped() && resident_file_bytes() > mapped_allowance) store->drop_pages();
  };
  // What the positions hold of the budget when mapped: their pages, up to the allowance (a small
  // input's whole vertex rows are less: counting the allowance kept inputs of a few hundred
  // thousand faces from going by parts under limits of tens of MB).
  const double mapped_resident =
      std::min(double(mapped_allowance), double(nv) * (map_input ? double(layout_row) : 12.0));
  const outofcore::StreamedPartsPlan plan =
      !soup && budget_binds && ooc.parts == 0 && partition_refusal(Mesh{}, options).empty()
          ? outofcore::plan_streamed_parts(report.input_faces, nv, std::size_t(target), budget,
                                           positions_in_memory ? 12.0 * double(nv) : mapped_resident, threads)
          : outofcore::StreamedPartsPlan{};
  SimplifyResult r;
  bool refit_to_input = false;
  bool by_parts = false;
  if (plan.parts > 0) {
    progress.phase("parts", 2);
    progress.start_phase2();
    outofcore::StreamedPartsReport parts_report;
    by_parts = outofcore::simplify_streamed_parts(
        path, positions, lo, extent, options, plan, temp_dir,
        [&](double f) {
          give_back_pages();
          progress.fraction(f);
        },
        r, &parts_report);
    if (by_parts) {
      if (store) store->release();
      report.method = "parts";
      report.parts = parts_report.parts;
      report.shared_vertices = parts_report.shared_vertices;
      report.merged_faces = parts_report.merged_faces;
      report.temp_bytes_written = outofcore::temp_bytes_written() - temp_bytes_before;
      lap("parts");
    }
  }
  if (!by_parts) {
    // --- phase 1: Lindstrom 2000 clustering, the grid sized by a sample ----------------------------
    progress.phase("clustering", 2);
    Grid fine;
    std::copy(lo, lo + 3, fine.lo);
    fine.size = starting_cell_size(sample, lo, extent, goal_cells);
    std::vector<float>().swap(sample);
    // The sample's estimate is a surface's (cells ~ resolution^2). Where the vertices are not
    // spread over the surface (a CAD model's lie along its edges, its flat faces have none inside)
    // a finer grid finds fewer new cells than that, the grid comes out too coarse, and the
    // clustered mesh could end below the target (trimesh_box10.stl, 8,954 faces, to 10 % under
    // 800 KB: 646 faces, Hausdorff 39 % of the diagonal). Such a grid is refined and the faces
    // clustered again, a pass over them each time, while their count grows.
    std::optional<TempFile> faces;
    std::optional<ParallelClustering> clustering;
    std::vector<std::uint32_t> indices;  // the clustered faces, of the cells' ids
    std::vector<std::uint64_t> shapes;   // per clustered face, its input triangle's
    for (std::uint64_t pass = 0, previous_faces = 0;; ++pass) {
      clustering.reset();
      faces.emplace(temp_dir, "faces");
      clustering.emplace(fine, hard_cells, threads, *faces);
      std::optional<MeshStream> again;  // the faces once more, for a refined grid
      if (pass > 0) {
        again.emplace(path);
        if (!soup) {  // the positions again (released after each pass, as the faces are read back)
          store = new_store();
          if (store->copied())
            again->read_vertices([&](const double* xyz, std::size_t n) { store->append(xyz, n); });
          positions = store->finish();
        }
      }
      MeshStream& source = again ? *again : in;
      clustering->after_block = [&, blocks = 0]() mutable {
        if (++blocks % 16 == 0) give_back_pages();
        progress.read(source.bytes_read());
      };
      if (soup) {
        source.read_soup([&](const double* xyz, std::size_t n) {
          clustering->add_soup(xyz, n);
          progress.read(source.bytes_read());
        });
      } else {
        source.read_triangles([&](const std::uint32_t* tri, std::size_t n) {
          clustering->add_indexed(tri, n, positions);
          progress.read(source.bytes_read());
        });
      }
      clustering->finish();
      if (store) store->release();
      // The faces on this grid (a thin plate's two sides clustered into one face pair drop out),
      // against the floor (about two a cell).
      shapes.clear();
      indices = outofcore::read_clustered_faces(*clustering, *faces, shapes);
      const std::uint64_t triples_now = indices.size() / 3;
      outofcore::drop_paired_faces(indices, shapes);
      const std::uint64_t faces_now = indices.size() / 3;
      // Walls thinner than a cell: their two sides come out on the same triples and cancel in
      // pairs, and where a quarter of the faces cancel so, whole walls are gone (trimesh_box10.stl
      // to 10 % under 800 KB: 42 % of the faces on the refined grid, an inner wall missing,
      // Hausdorff 39 % of the diagonal; a scan's thin parts cancel 15 % at most in ../shared/data).
      const bool walls_lost = 4 * (triples_now - faces_now) > triples_now;
      const bool too_coarse = (faces_now < floor_cells || walls_lost) && clustering->levels() == 0 &&
                              fine.size > extent / kFinestResolution &&
                              (pass == 0 || double(faces_now) > kRegridGrowth * double(previous_faces));
      if (!too_coarse || pass == kMaxRegrids) break;
      const double finer =
          std::sqrt(2.0 * double(goal_cells) / double(std::max<std::uint64_t>(faces_now, 1)));
      fine.size = std::max(extent / kFinestResolution, fine.size / std::clamp(finer, 1.5, 8.0));
      previous_faces = faces_now;
      ++report.grid_refinements;
      progress.add_pass(in.file_size());
    }
    report.grid_coarsenings = unsigned(clustering->levels());
    CellTable& cells = clustering->cells();
    report.clustered_vertices = cells.size();
    const double cell_size = fine.size * std::ldexp(1.0, clustering->levels());
    report.grid_resolution = std::uint64_t(std::ceil(extent / cell_size));

    // Each cell's representative: the minimum of its quadric around the corners' mean, kept inside
    // the cell (Lindstrom & Silva 2001 §4: a point outside would fold neighbouring cells' faces).
    // Each cell on its own, so the threads share them in ranges without changing a bit.
    Mesh clustered_mesh;
    clustered_mesh.positions.resize(3 * std::size_t(cells.size()));
    auto place_cells = [&](std::uint32_t begin, std::uint32_t end) {
      for (std::uint32_t i = begin; i < end; ++i) {
        const auto& cell = cells.cell(i);
        const double mean[3] = {cell.sum[0] / cell.corners, cell.sum[1] / cell.corners,
                                cell.sum[2] / cell.corners};
        double x[3];
        const core::Quadric q = with_border(cell, cell_size);
        cluster_detail::minimize_around(q, mean, x);
        std::uint64_t k[3];
        outofcore::unpack_cell(cells.key(i), k);
        const double c0[3] = {double(k[0]) * cell_size, double(k[1]) * cell_size, double(k[2]) * cell_size};
        const double c1[3] = {c0[0] + cell_size, c0[1] + cell_size, c0[2] + cell_size};
        pull_into_cell(q, mean, c0, c1, x);
        for (int a = 0; a < 3; ++a) clustered_mesh.positions[3 * i + a] = lo[a] + x[a];
      }
    };
    {
      std::vector<std::thread> helpers;
      const std::uint32_t n = cells.size(), per = n / threads + 1;
      for (unsigned t = 1; t < threads && t * per < n; ++t)
        helpers.emplace_back(place_cells, t * per, std::min<std::uint32_t>(n, (t + 1) * per));
      place_cells(0, std::min(n, per));
      for (std::thread& h : helpers) h.join();
    }
    cells.release();
    clustered_mesh.indices = std::move(indices);
    std::vector<std::uint64_t>().swap(shapes);
    report.clustered_faces = clustered_mesh.face_count();
    report.temp_bytes_written = outofcore::temp_bytes_written() - temp_bytes_before;
    lap("clustering");

    // --- phase 2: GH97 in core on the clustered mesh, part by part when it is large -------------------
    progress.phase("simplifying", 3);
    progress.start_phase2();
    // Where the memory limit leaves phase 2 fewer than 6 clustered faces an output face, its own
    // refit (to the clustered mesh) gets fewer rounds than an in-core run's or none (below 3): the
    // refit then fits the output to the input's points after phase 2 instead, the clustered surface
    // having lost what the cells averaged away besides (a one-pixel spike on the terrain). From 6
    // up phase 2 refits as before: its refit to the clustered mesh has the input's area weights and
    // the guard against moving off the surface, which the streamed points lack, and came out
    // better (the generated 1.3M sphere to 1 %, 35x: E 1.06x the in-core run's, 1.08x fitted to the input).
    const double target_faces_estimate =
        options.target_faces ? double(options.target_faces) : 2.0 * double(options.target_vertices);
    refit_to_input = options.refit_rounds > 0 && options.refit_by_reduction &&
                     double(report.clustered_faces) < 6 * target_faces_estimate;
    const SimplifyOptions phase2_options = [&] {
      SimplifyOptions o = options;
      if (refit_to_input) o.refit_rounds = 0;
      o.far_repair = false;  // not measured out of core (docs/benchmarks.md, "Far places")
      return o;
    }();
    const unsigned parts = ooc.parts ? ooc.parts
                           : partition_refusal(clustered_mesh, options).empty()
                               ? automatic_parts(clustered_mesh.face_count())
                               : 1;
    if (parts > 1) {
      PartitionOptions po;
      po.parts = parts;
      po.progress = [&](unsigned done, unsigned all) {
        progress.fraction(0.9 * double(done) / double(all));
        return true;
      };
      PartitionReport pr;
      r = simplify_partitioned(clustered_mesh, phase2_options, po, &pr);
      report.parts = pr.parts;
    } else {
      Phase2Observer observer(progress);
      r = simplify(std::move(clustered_mesh), phase2_options, &observer);
      report.parts = 1;
    }
    Phase2Observer folds_observer(progress);
    if (past_the_folds(r, phase2_options, &folds_observer)) {
      report.topology_relaxed = true;
      refit_to_input = options.refit_rounds > 0;  // the first run's refit fitted the clustered surface
    }
    lap("simplifying");
  }
  // The refit against the input (see phase2_options): whether it runs and its points a vertex
  // follow the reduction from the input, as an in-core run's would; its points fit in the budget.
  RefitOptions refit = refit_options_for(options, std::size_t(std::min<std::uint64_t>(report.input_vertices, SIZE_MAX)),
                                         r.mesh.vertex_count());
  const std::size_t points_wanted = refit_points_within(refit, r.mesh, budget);
  if (refit_to_input && refit.rounds > 0 && r.contractions > 0 && points_wanted > 0) {
    progress.phase("refitting", 3);
    // Phase 2's freed memory goes back to the system, so that the refit's peak adds to the
    // output's, not to phase 2's.
    core::release_free_memory();
    const std::uint64_t points_in_file = soup ? 3 * report.input_faces : report.input_vertices;
    std::vector<double> xyz = input_points(path, double(points_wanted), points_in_file);
    const std::vector<double> weights(xyz.size() / 3, 1.0);
    const refit_detail::FitPoints points(xyz, weights);
    std::vector<double>().swap(xyz);
    refit.points_per_vertex = 0;  // thinned above
    // One round: without the guard a second one pushed the generated sphere's farthest output
    // point out (Hausdorff 1.31x -> 1.37x the in-core run's at 10 %) for the same E (1.25x); on
    // the terrain and the torus it changed E by under 1.5 % (docs/benchmarks.md).
    refit.rounds = 1;
    const RefitResult fit = refit_detail::refit_to_points(points, r.mesh, refit);
    r.refit_rms_before = fit.rms_before;
    r.refit_rms_after = fit.rms_after;
    r.refit_rounds = fit.rounds;
    lap("refitting");
  }
  report.peak_memory_bytes = peak_rss_bytes();
  if (report_out) *report_out = std::move(report);
  return r;
}

}  // namespace qem
