// Garland & Shaffer 2002's two phases: Lindstrom 2000 out-of-core clustering (this file's
// cluster_stream), then GH97 in core (qem::simplify) on the clustered mesh.
#include "qem/out_of_core.h"

#include <fcntl.h>
#include <sys/mman.h>
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
#include <sstream>

#include "cluster/cluster_quadric.h"
#include "core/quadric.h"
#include "outofcore/cell_table.h"
#include "outofcore/mesh_stream.h"
#include "outofcore/temp_file.h"
#include "qem/error.h"

namespace qem {
namespace {

using outofcore::CellKey;
using outofcore::CellSet;
using outofcore::CellTable;
using outofcore::MeshStream;
using outofcore::TempFile;

/// Peak memory of the in-core path per input face (load, working mesh, heap, refit), the figure
/// measured for issue 20; the decision in-core / out-of-core uses it.
constexpr double kInCoreBytesPerFace = 180;
/// Phase 1 per occupied cell: its quadric and corner sum (15 doubles) and its hash slot (at most
/// half full). Phase 2 per cell: about 1.6 faces (measured on the spheres), each taking the
/// in-core path's bytes plus the clustered mesh handed to it and the pairing of its faces; 2 GB
/// held 8 million clustered faces at 1.99 GB peak with 2 faces a cell and 180 bytes a face, hence
/// the margin.
constexpr double kClusterBytesPerCell = 160;
constexpr double kPhase2BytesPerCell = 520;
/// The finest grid: 2^20 cells along the longest side (keys hold 21 bits an axis).
constexpr double kFinestResolution = double(1 << 20);

std::uint64_t peak_rss_bytes() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::strtoull(line.c_str() + 6, nullptr, 10) * 1024;
  return 0;
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
  void read(std::uint64_t bytes_read) {
    // A pass may read a buffer's worth past its element: the total counts each byte once.
    p_.bytes_read = std::min(bytes_read, p_.bytes_total);
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

/// The input's positions as float (12 bytes a vertex), in memory when they fit the budget, else
/// in a temporary file mapped read-only, whose pages the kernel can drop and read again.
class PositionStore {
 public:
  PositionStore(std::uint64_t vertices, bool in_memory, const std::string& temp_dir) : count_(vertices) {
    if (in_memory) {
      memory_.reserve(3 * vertices);
    } else {
      file_ = std::make_unique<TempFile>(temp_dir, "positions");
    }
  }
  ~PositionStore() {
    if (map_) ::munmap(map_, map_bytes_);
  }
  void append(const double* xyz, std::size_t n) {
    for (std::size_t i = 0; i < 3 * n; ++i) {
      const float f = static_cast<float>(xyz[i]);
      if (file_)
        file_->put(f);
      else
        memory_.push_back(f);
    }
  }
  /// After the last append: the positions, 3 floats a vertex.
  const float* finish() {
    if (!file_) return memory_.data();
    file_->flush();
    map_bytes_ = std::size_t(count_) * 12;
    if (map_bytes_ == 0) return nullptr;
    int fd = ::open(file_->path().c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw Error(file_->path() + ": cannot reopen: " + std::strerror(errno));
    map_ = ::mmap(nullptr, map_bytes_, PROT_READ, MAP_SHARED, fd, 0);
    ::close(fd);
    if (map_ == MAP_FAILED) {
      map_ = nullptr;
      throw Error(file_->path() + ": cannot map: " + std::strerror(errno));
    }
    return static_cast<const float*>(map_);
  }
  void release() {
    if (map_) ::munmap(map_, map_bytes_);
    map_ = nullptr;
    std::vector<float>().swap(memory_);
    file_.reset();
  }

 private:
  std::uint64_t count_;
  std::vector<float> memory_;
  std::unique_ptr<TempFile> file_;
  void* map_ = nullptr;
  std::size_t map_bytes_ = 0;
};

/// The grid: cubic cells of side `size` from the box's low corner.
struct Grid {
  double lo[3] = {0, 0, 0};
  double size = 1;
  CellKey key(double x, double y, double z) const {
    const double c[3] = {x, y, z};
    std::uint64_t k[3];
    for (int a = 0; a < 3; ++a) {
      double t = std::floor((c[a] - lo[a]) / size);
      k[a] = std::uint64_t(std::clamp(t, 0.0, double((1u << 21) - 1)));
    }
    return outofcore::pack_cell(k[0], k[1], k[2]);
  }
};

/// Picks the finest grid whose occupied cells stay within `max_cells` (Lindstrom 2000 sizes the
/// grid by hand; here it follows the budget). Four families of grids, their cell sizes a quarter
/// octave apart, each coarsened by halves while its cells exceed the budget (cells of twice the
/// side are unions of eight, so the count stays exact): one pass over the positions, and the
/// chosen grid is within 2^(1/4) of the finest that fits.
class GridChooser {
 public:
  GridChooser(const double lo[3], double start_size, std::uint64_t max_cells) : max_cells_(max_cells) {
    std::copy(lo, lo + 3, grid_.lo);
    for (int f = 0; f < 4; ++f)
      families_.push_back({CellSet(max_cells), start_size * std::pow(2.0, f / 4.0)});
  }
  void add(double x, double y, double z) {
    for (Family& fam : families_) {
      grid_.size = fam.size;
      fam.set.insert(grid_.key(x, y, z));
      while (fam.set.size() > max_cells_) fam.set.coarsen(), fam.size *= 2;
    }
  }
  Grid best() const {
    Grid g = grid_;
    g.size = std::numeric_limits<double>::infinity();
    for (const Family& fam : families_) g.size = std::min(g.size, fam.size);
    return g;
  }

 private:
  struct Family {
    CellSet set;
    double size;
  };
  std::uint64_t max_cells_;
  Grid grid_;
  std::vector<Family> families_;
};

/// Where GridChooser starts: every coarsening rebuilds a table of the budget's size, so starting
/// at the finest grid costs a dozen rebuilds a family. A sample of the points counts the occupied
/// cells at coarse grids, where each cell holds many samples and the count is close to the
/// input's; a surface's count grows with the square of the resolution, which extrapolates it to
/// the budget. Starting 2x finer than that leaves room for a surface that is rougher than the
/// sample shows; a grid too fine only costs rebuilds.
double starting_cell_size(const std::vector<float>& sample, const double lo[3], double extent,
                          std::uint64_t max_cells) {
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
  const double estimate = resolution * std::sqrt(double(max_cells) / cells);
  return extent / std::min(kFinestResolution, 2 * estimate);
}

/// Clustering maps the closed input surface onto a surface that is closed in the mod-2 sense:
/// every edge of the cell triples is used an even number of times (the image of a cycle is a
/// cycle). Where a thin part or a fold collapses, the same three cells come out twice (or four
/// times...); the in-core simplifier would keep one of them and open a crack. Dropping the triples
/// that come out an even number of times and keeping one of those that come out an odd number
/// keeps every edge's count even: no boundary edge the input did not have.
void drop_paired_faces(std::vector<std::uint32_t>& indices) {
  const std::size_t nf = indices.size() / 3;
  auto sorted_key = [&](std::size_t f) {
    std::array<std::uint32_t, 3> t{indices[3 * f], indices[3 * f + 1], indices[3 * f + 2]};
    std::sort(t.begin(), t.end());
    return t;
  };
  std::vector<std::uint32_t> order(nf);
  for (std::size_t f = 0; f < nf; ++f) order[f] = std::uint32_t(f);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const auto ka = sorted_key(a), kb = sorted_key(b);
    return ka != kb ? ka < kb : a < b;
  });
  std::vector<bool> keep(nf, false);
  for (std::size_t i = 0; i < nf;) {
    std::size_t j = i + 1;
    const auto k = sorted_key(order[i]);
    while (j < nf && sorted_key(order[j]) == k) ++j;
    if ((j - i) % 2 == 1) keep[order[i]] = true;  // the first in file order
    i = j;
  }
  std::size_t out = 0;
  for (std::size_t f = 0; f < nf; ++f)
    if (keep[f]) {
      for (int c = 0; c < 3; ++c) indices[3 * out + c] = indices[3 * f + c];
      ++out;
    }
  indices.resize(3 * out);
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
  const bool soup = !in.indexed();
  // A ratio is of the input's faces, not of the clustered mesh phase 2 starts from.
  SimplifyOptions options = input_options;
  if (options.target_ratio > 0) {
    const auto by_ratio = std::size_t(std::floor(options.target_ratio * double(report.input_faces)));
    options.target_faces = options.target_faces ? std::min(options.target_faces, by_ratio) : by_ratio;
    options.target_ratio = 0;
  }
  Progress progress(ooc, 4);
  // The passes over the file: PLY once (vertices, then faces), STL three times (bounds, grid, clusters).
  progress.set_total(soup ? 3 * in.file_size() : in.file_size());
  auto lap = [&, t = 0.0](const char* name) mutable {
    const double now = progress.seconds();
    report.phases.push_back({name, now - t});
    t = now;
  };

  // The budget: 90 % of the limit (the rest for the program itself and the read buffers).
  const double budget = 0.9 * double(report.memory_limit);
  const std::uint64_t nv = in.vertex_count();
  const bool positions_in_memory = !soup && 12.0 * double(nv) <= budget / 3;

  const double phase1_room = budget - (positions_in_memory ? 12.0 * double(nv) : 0.0);
  std::uint64_t max_cells = std::uint64_t(
      std::max(0.0, std::min(phase1_room / kClusterBytesPerCell, budget / kPhase2BytesPerCell)));
  // Never fewer cells than the target's vertices, or phase 2 would have nothing to choose from.
  max_cells = std::max<std::uint64_t>({max_cells, options.target_faces, options.target_vertices * 2, 1024});

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
  std::uint64_t seen = 0;
  auto grow = [&](const double* xyz, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i, ++seen) {
      for (int a = 0; a < 3; ++a) {
        // As float, the precision the positions are kept in (and every cell is computed from).
        const double v = static_cast<float>(xyz[3 * i + a]);
        lo[a] = std::min(lo[a], v), hi[a] = std::max(hi[a], v);
      }
      if (seen % sample_step == 0)
        sample.insert(sample.end(), {float(xyz[3 * i]), float(xyz[3 * i + 1]), float(xyz[3 * i + 2])});
    }
    progress.read(in.bytes_read());
  };
  std::unique_ptr<PositionStore> store;
  const float* positions = nullptr;
  if (soup) {
    in.read_soup([&](const double* xyz, std::size_t n) { grow(xyz, 3 * n); });
  } else {
    store = std::make_unique<PositionStore>(nv, positions_in_memory, temp_dir);
    in.read_vertices([&](const double* xyz, std::size_t n) {
      store->append(xyz, n);
      grow(xyz, n);
    });
    positions = store->finish();
  }
  if (report.input_faces == 0 || !(lo[0] <= hi[0])) throw Error(path + ": no faces to simplify");
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-30});
  lap("bounds");

  // --- the grid: as fine as the budget allows -----------------------------------------------------
  progress.phase("grid", 2);
  GridChooser chooser(lo, starting_cell_size(sample, lo, extent, max_cells), max_cells);
  std::vector<float>().swap(sample);
  if (soup) {
    // The positions are not kept: the grid's pass reads the file again.
    in.read_soup([&](const double* xyz, std::size_t n) {
      for (std::size_t i = 0; i < 3 * n; ++i)
        chooser.add(float(xyz[3 * i]), float(xyz[3 * i + 1]), float(xyz[3 * i + 2]));
      progress.read(in.bytes_read());
    });
  } else {
    for (std::uint64_t v = 0; v < nv; ++v)
      chooser.add(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
  }
  const Grid grid = chooser.best();
  report.grid_resolution = std::uint64_t(std::ceil(extent / grid.size));
  lap("grid");

  // --- phase 1: Lindstrom 2000 clustering ----------------------------------------------------------
  // Every triangle's plane quadric, weighted by its area (HG99, as the in-core default), is added
  // to the cell of each of its corners; the triangles whose corners fall in three different cells
  // survive as cell triples, written to a temporary file.
  progress.phase("clustering", 3);
  CellTable cells(max_cells);
  TempFile faces(temp_dir, "faces");
  std::uint64_t clustered = 0;
  auto add_triangle = [&](const double p[9]) {
    std::uint32_t id[3];
    for (int k = 0; k < 3; ++k) id[k] = cells.find_or_add(grid.key(p[3 * k], p[3 * k + 1], p[3 * k + 2]));
    // Local coordinates (from the box corner) keep the quadric's constant term small.
    const Vec3 a{p[0] - lo[0], p[1] - lo[1], p[2] - lo[2]};
    const Vec3 b{p[3] - lo[0], p[4] - lo[1], p[5] - lo[2]};
    const Vec3 c{p[6] - lo[0], p[7] - lo[1], p[8] - lo[2]};
    const Vec3 nrm = cross(b - a, c - a);
    const double len = length(nrm);
    if (len > 0) {
      const Vec3 u = nrm / len;
      const core::Quadric q = core::Quadric::plane(u, -dot(u, a), len / 2);
      for (int k = 0; k < 3; ++k) cells.cell(id[k]).quadric += q;
    }
    const Vec3* corner[3] = {&a, &b, &c};
    for (int k = 0; k < 3; ++k) {
      auto& cell = cells.cell(id[k]);
      cell.sum[0] += corner[k]->x, cell.sum[1] += corner[k]->y, cell.sum[2] += corner[k]->z;
      cell.corners += 1;
    }
    if (id[0] != id[1] && id[1] != id[2] && id[0] != id[2]) {
      faces.write(id, sizeof id);
      ++clustered;
    }
  };
  if (soup) {
    in.read_soup([&](const double* xyz, std::size_t n) {
      double p[9];
      for (std::size_t t = 0; t < n; ++t) {
        for (int k = 0; k < 9; ++k) p[k] = static_cast<float>(xyz[9 * t + k]);
        add_triangle(p);
      }
      progress.read(in.bytes_read());
    });
  } else {
    in.read_triangles([&](const std::uint32_t* tri, std::size_t n) {
      double p[9];
      for (std::size_t t = 0; t < n; ++t) {
        for (int k = 0; k < 3; ++k)
          for (int a = 0; a < 3; ++a) p[3 * k + a] = positions[3 * std::size_t(tri[3 * t + k]) + a];
        add_triangle(p);
      }
      progress.read(in.bytes_read());
    });
  }
  if (store) store->release();
  report.clustered_vertices = cells.size();

  // Each cell's representative: the minimum of its quadric around the corners' mean, kept inside
  // the cell (Lindstrom & Silva 2001 §4: a point outside would fold neighbouring cells' faces).
  Mesh clustered_mesh;
  clustered_mesh.positions.resize(3 * cells.size());
  for (std::uint32_t i = 0; i < cells.size(); ++i) {
    const auto& cell = cells.cell(i);
    const double mean[3] = {cell.sum[0] / cell.corners, cell.sum[1] / cell.corners,
                            cell.sum[2] / cell.corners};
    double x[3];
    cluster_detail::minimize_around(cell.quadric, mean, x);
    std::uint64_t k[3];
    outofcore::unpack_cell(cells.key(i), k);
    for (int a = 0; a < 3; ++a) {
      const double c0 = double(k[a]) * grid.size, c1 = c0 + grid.size;
      clustered_mesh.positions[3 * i + a] = lo[a] + std::clamp(x[a], c0, c1);
    }
  }
  cells.release();
  lap("clustering");

  // --- phase 2: GH97 in core on the clustered mesh ------------------------------------------------
  progress.phase("simplifying", 4);
  progress.start_phase2();
  faces.rewind_for_reading();
  clustered_mesh.indices.resize(3 * clustered);
  if (faces.read(clustered_mesh.indices.data(), 12 * clustered) != 12 * clustered)
    throw Error(faces.path() + ": the temporary file is shorter than written");
  drop_paired_faces(clustered_mesh.indices);
  report.clustered_faces = clustered_mesh.face_count();
  report.temp_bytes_written = outofcore::temp_bytes_written() - temp_bytes_before;
  Phase2Observer observer(progress);
  SimplifyResult r = simplify(std::move(clustered_mesh), options, &observer);
  lap("simplifying");
  report.peak_memory_bytes = peak_rss_bytes();
  if (report_out) *report_out = std::move(report);
  return r;
}

}  // namespace qem
