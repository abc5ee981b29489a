#include "outofcore/parallel_clustering.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>

#include "geometry/vec3.h"
#include "qem/error.h"

namespace qem::outofcore {

namespace {

/// One block's cells, numbered in the order its triangles meet them: open addressing over flat
/// arrays, emptied between blocks by clearing only the slots used.
class BlockCells {
 public:
  std::vector<CellKey> keys;
  std::vector<CellSums> sums;

  std::uint32_t find_or_add(CellKey key) {
    if (2 * (keys.size() + 1) > slots_.size()) grow();
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t s = slot_of(key, mask);; s = (s + 1) & mask) {
      if (slots_[s].key == key) return slots_[s].id;
      if (slots_[s].key == 0) {
        slots_[s] = {key, std::uint32_t(keys.size())};
        keys.push_back(key);
        sums.emplace_back();
        return slots_[s].id;
      }
    }
  }
  void clear() {
    const std::size_t mask = slots_.size() - 1;
    for (CellKey k : keys)
      for (std::size_t s = slot_of(k, mask);; s = (s + 1) & mask)
        if (slots_[s].key == k) {
          slots_[s].key = 0;
          break;
        }
    // Open addressing: a cleared slot may sit inside another key's probe run, but every key of the
    // block is cleared, so the table ends empty.
    keys.clear();
    sums.clear();
  }

 private:
  struct Slot {
    CellKey key = 0;
    std::uint32_t id = 0;
  };
  void grow() {
    std::vector<Slot> slots(std::max<std::size_t>(4096, 2 * slots_.size()));
    const std::size_t mask = slots.size() - 1;
    for (const Slot& old : slots_)
      if (old.key) {
        std::size_t t = slot_of(old.key, mask);
        while (slots[t].key) t = (t + 1) & mask;
        slots[t] = old;
      }
    slots_.swap(slots);
  }
  std::vector<Slot> slots_;
};

// The triangle's shape: a hash of its three corners' coordinates, in no order of corners, so that a
// triangle and its reversed copy (a two-sided sheet's back face, on the same vertices or on others
// at the same places) have the same shape and other triangles, almost surely, other shapes.
std::uint64_t shape_of(const double p[9]) {
  std::array<std::array<std::uint64_t, 3>, 3> c;
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a) c[k][a] = std::bit_cast<std::uint64_t>(p[3 * k + a] + 0.0);  // -0 as 0
  std::sort(c.begin(), c.end());
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (const auto& corner : c)
    for (std::uint64_t x : corner) {  // splitmix64 steps
      h ^= x + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
      h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
      h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
      h ^= h >> 31;
    }
  return h;
}

}  // namespace

struct ParallelClustering::Block {
  std::uint64_t index = 0;
  std::vector<std::uint32_t> corners;  // indexed input
  std::vector<float> xyz;              // soup input
  BlockCells cells;
  std::vector<std::uint32_t> triples;  // block-local cell ids
  std::vector<std::uint64_t> shapes;   // per triple, its triangle's shape_of
  const PositionSource* positions = nullptr;
  bool done = false;

  std::size_t triangles() const { return corners.empty() ? xyz.size() / 9 : corners.size() / 3; }

  /// Lindstrom 2000 §3 for this block's triangles: each triangle's plane quadric, weighted by its
  /// area (HG99, as the in-core default), is added to the cell of each corner, with the corner;
  /// the triangles whose corners fall in three cells are kept as triples.
  void cluster(const Grid& grid) {
    cells.clear();
    triples.clear();
    shapes.clear();
    const std::size_t n = triangles();
    double p[9];
    for (std::size_t t = 0; t < n; ++t) {
      if (!corners.empty()) {
        for (int k = 0; k < 3; ++k) positions->get(corners[3 * t + k], p + 3 * k);
      } else {
        for (int k = 0; k < 9; ++k) p[k] = xyz[9 * t + k];
      }
      std::uint32_t id[3];
      CellKey key[3];
      for (int k = 0; k < 3; ++k) {
        key[k] = grid.key(p[3 * k], p[3 * k + 1], p[3 * k + 2]);
        // Neighbouring corners mostly share a cell: no lookup for a repeat.
        id[k] = k > 0 && key[k] == key[k - 1] ? id[k - 1]
                : k > 1 && key[k] == key[0]   ? id[0]
                                              : cells.find_or_add(key[k]);
      }
      // Local coordinates (from the box corner) keep the quadric's constant term small.
      const Vec3 a{p[0] - grid.lo[0], p[1] - grid.lo[1], p[2] - grid.lo[2]};
      const Vec3 b{p[3] - grid.lo[0], p[4] - grid.lo[1], p[5] - grid.lo[2]};
      const Vec3 c{p[6] - grid.lo[0], p[7] - grid.lo[1], p[8] - grid.lo[2]};
      const Vec3 nrm = cross(b - a, c - a);
      const double len = length(nrm);
      const Vec3* corner[3] = {&a, &b, &c};
      const core::Quadric q =
          len > 0 ? core::Quadric::plane(nrm / len, -dot(nrm / len, a), len / 2) : core::Quadric{};
      for (int k = 0; k < 3; ++k) {
        CellSums& cell = cells.sums[id[k]];
        if (len > 0) cell.quadric += q;
        cell.sum[0] += corner[k]->x, cell.sum[1] += corner[k]->y, cell.sum[2] += corner[k]->z;
        cell.corners += 1;
      }
      // The directed edges, each to the cells of its two ends (once when they share one).
      for (int k = 0; k < 3; ++k) {
        const Vec3& from = *corner[k];
        const Vec3& to = *corner[(k + 1) % 3];
        const Vec3 e = to - from, m = cross(from, to);
        const std::uint32_t ends[2] = {id[k], id[(k + 1) % 3]};
        for (int j = 0; j < (ends[0] == ends[1] ? 1 : 2); ++j) {
          CellSums& cell = cells.sums[ends[j]];
          cell.edge[0] += e.x, cell.edge[1] += e.y, cell.edge[2] += e.z;
          cell.moment[0] += m.x, cell.moment[1] += m.y, cell.moment[2] += m.z;
        }
      }
      if (id[0] != id[1] && id[1] != id[2] && id[0] != id[2]) {
        triples.insert(triples.end(), {id[0], id[1], id[2]});
        shapes.push_back(shape_of(p));
      }
    }
  }
};

struct ParallelClustering::Workers {
  std::mutex mutex;
  std::condition_variable work, finished;
  std::deque<Block*> queue;
  std::vector<std::unique_ptr<Block>> in_flight;  // in block order
  std::vector<std::thread> threads;
  std::exception_ptr failure;
  bool stop = false;

  void run(const Grid& grid) {
    std::unique_lock lock(mutex);
    for (;;) {
      work.wait(lock, [&] { return stop || !queue.empty(); });
      if (stop) return;
      Block* b = queue.front();
      queue.pop_front();
      lock.unlock();
      try {
        b->cluster(grid);
      } catch (...) {
        lock.lock();
        if (!failure) failure = std::current_exception();
        b->done = true;
        finished.notify_all();
        continue;
      }
      lock.lock();
      b->done = true;
      finished.notify_all();
    }
  }
};

ParallelClustering::ParallelClustering(const Grid& fine, std::uint64_t max_cells, unsigned threads,
                                       TempFile& faces)
    : fine_(fine),
      max_cells_(std::max<std::uint64_t>(max_cells, 1)),
      faces_(faces),
      cells_(std::size_t(max_cells_)) {
  if (threads > 1) {
    workers_ = std::make_unique<Workers>();
    for (unsigned t = 0; t < threads; ++t) workers_->threads.emplace_back([this] { workers_->run(fine_); });
  }
}

ParallelClustering::~ParallelClustering() {
  if (!workers_) return;
  {
    std::lock_guard lock(workers_->mutex);
    workers_->stop = true;
  }
  workers_->work.notify_all();
  for (std::thread& t : workers_->threads) t.join();
}

void ParallelClustering::start_block() {
  if (!spare_.empty()) {
    filling_ = std::move(spare_.back());
    spare_.pop_back();
  } else {
    filling_ = std::make_unique<Block>();
  }
  filling_->corners.clear(), filling_->xyz.clear();
  filling_->positions = nullptr;
}

void ParallelClustering::add_indexed(const std::uint32_t* corners, std::size_t n,
                                     const PositionSource& positions) {
  while (n > 0) {
    if (!filling_) start_block();
    filling_->positions = &positions;
    const std::size_t take = std::min(n, kBlockTriangles - filling_->triangles());
    filling_->corners.insert(filling_->corners.end(), corners, corners + 3 * take);
    corners += 3 * take, n -= take;
    if (filling_->triangles() == kBlockTriangles) submit();
  }
}

void ParallelClustering::add_soup(const double* xyz, std::size_t n) {
  while (n > 0) {
    if (!filling_) start_block();
    const std::size_t take = std::min(n, kBlockTriangles - filling_->triangles());
    for (std::size_t i = 0; i < 9 * take; ++i) filling_->xyz.push_back(static_cast<float>(xyz[i]));
    xyz += 9 * take, n -= take;
    if (filling_->triangles() == kBlockTriangles) submit();
  }
}

void ParallelClustering::submit() {
  std::unique_ptr<Block> b = std::move(filling_);
  b->index = submitted_++;
  b->done = false;
  if (!workers_) {
    b->cluster(fine_);
    add_block(*b);
    spare_.push_back(std::move(b));
    return;
  }
  {
    std::lock_guard lock(workers_->mutex);
    workers_->queue.push_back(b.get());
    workers_->in_flight.push_back(std::move(b));
  }
  workers_->work.notify_one();
  // Bounded memory: at most a few blocks waiting or being clustered per thread.
  for (;;) {
    merge_ready(false);
    if (workers_->in_flight.size() < 2 * workers_->threads.size() + 2) break;
    std::unique_lock lock(workers_->mutex);
    workers_->finished.wait(lock, [&] { return workers_->in_flight.front()->done; });
  }
}

void ParallelClustering::merge_ready(bool wait_all) {
  for (;;) {
    std::unique_ptr<Block> b;
    {
      std::unique_lock lock(workers_->mutex);
      if (workers_->in_flight.empty()) return;
      if (wait_all) workers_->finished.wait(lock, [&] { return workers_->in_flight.front()->done; });
      if (!workers_->in_flight.front()->done) return;
      if (workers_->failure) std::rethrow_exception(workers_->failure);
      b = std::move(workers_->in_flight.front());
      workers_->in_flight.erase(workers_->in_flight.begin());
    }
    add_block(*b);
    spare_.push_back(std::move(b));
  }
}

void ParallelClustering::add_block(Block& block) {
  for (std::size_t i = 0; i < block.cells.keys.size(); ++i)
    cells_.cell(cells_.find_or_add(coarser_cell(block.cells.keys[i], levels_))) += block.cells.sums[i];
  for (std::size_t t = 0; t < block.shapes.size(); ++t) {
    for (int k = 0; k < 3; ++k) faces_.put(block.cells.keys[block.triples[3 * t + k]]);
    faces_.put(block.shapes[t]);
  }
  triples_ += block.shapes.size();
  while (cells_.size() > max_cells_) {
    cells_.coarsen();
    ++levels_;
  }
  ++merged_;
  if (after_block) after_block();
}

void ParallelClustering::finish() {
  if (filling_ && filling_->triangles() > 0) submit();
  if (workers_) merge_ready(true);
}

std::vector<std::uint32_t> read_clustered_faces(ParallelClustering& clustering, TempFile& faces,
                                                std::vector<std::uint64_t>& shapes) {
  faces.rewind_for_reading();
  const CellTable& cells = clustering.cells();
  const int levels = clustering.levels();
  std::vector<std::uint32_t> indices;
  shapes.clear();
  std::vector<CellKey> buf(4 << 16);  // per triple: three cell keys and the triangle's shape
  std::uint64_t left = clustering.triples();
  while (left > 0) {
    const std::size_t n = std::size_t(std::min<std::uint64_t>(left, buf.size() / 4));
    if (faces.read(buf.data(), 32 * n) != 32 * n)
      throw Error(faces.path() + ": the temporary file is shorter than written");
    for (std::size_t t = 0; t < n; ++t) {
      std::uint32_t id[3];
      for (int k = 0; k < 3; ++k) {
        id[k] = cells.find(coarser_cell(buf[4 * t + k], levels));
        if (id[k] == CellTable::kNoCell) throw Error(faces.path() + ": a face names a cell never met");
      }
      if (id[0] != id[1] && id[1] != id[2] && id[0] != id[2]) {
        indices.insert(indices.end(), {id[0], id[1], id[2]});
        shapes.push_back(buf[4 * t + 3]);
      }
    }
    left -= n;
  }
  return indices;
}

void drop_paired_faces(std::vector<std::uint32_t>& indices, const std::vector<std::uint64_t>& shapes) {
  const std::size_t nf = indices.size() / 3;
  // Each face as its sorted corners and its place in the file: sorting these groups the faces on
  // one triple, the first in file order leading each group.
  std::vector<std::array<std::uint32_t, 4>> order(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    std::array<std::uint32_t, 4>& t = order[f];
    t = {indices[3 * f], indices[3 * f + 1], indices[3 * f + 2], std::uint32_t(f)};
    std::sort(t.begin(), t.begin() + 3);
  }
  std::sort(order.begin(), order.end());
  std::vector<bool> keep(nf, false);
  auto same_face = [&](std::size_t i, std::size_t j) {
    return order[i][0] == order[j][0] && order[i][1] == order[j][1] && order[i][2] == order[j][2];
  };
  for (std::size_t i = 0; i < nf;) {
    std::size_t j = i + 1;
    while (j < nf && same_face(i, j)) ++j;
    bool copies = true;  // all of one input triangle
    for (std::size_t k = i + 1; k < j && copies; ++k) copies = shapes[order[k][3]] == shapes[order[i][3]];
    if (copies) {
      for (std::size_t k = i; k < j; ++k) keep[order[k][3]] = true;
    } else if ((j - i) % 2 == 1) {
      keep[order[i][3]] = true;  // the first in file order
    }
    i = j;
  }
  std::vector<std::array<std::uint32_t, 4>>().swap(order);
  std::size_t out = 0;
  for (std::size_t f = 0; f < nf; ++f)
    if (keep[f]) {
      for (int c = 0; c < 3; ++c) indices[3 * out + c] = indices[3 * f + c];
      ++out;
    }
  indices.resize(3 * out);
}

}  // namespace qem::outofcore
