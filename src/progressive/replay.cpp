// Replaying a prefix of a Record (GH97 §3: any M_i between M_n and M_g from one run).
//
// A contraction (v1, v2) -> v1 replaces v2 by v1 in every live face (GH97 §4), so after a prefix
// a base corner c stands for find(c), the end of the chain c -> kept -> kept of that ... : a
// union-find without ranks, since each removed vertex points at exactly one survivor. Applying a
// contraction is O(1 + dead faces); building a mesh is one pass over the faces with path
// compression, then a pass over the vertices, mirroring build_output in src/core/working_mesh.cpp:
// survivors in base (= input) order, faces in base (= input) order, moved vertices at their last
// recorded position, the others at their exact base coordinates.
#include <algorithm>
#include <numeric>
#include <vector>

#include "qem/progressive.h"

namespace qem {

namespace {

constexpr std::uint32_t kNone = 0xffffffffu;

class Replayer {
 public:
  explicit Replayer(const Record& r)
      : r_(r),
        parent_(r.base.vertex_count(), kNone),
        last_move_(r.base.vertex_count(), kNone),
        face_dead_(r.base.face_count(), 0),
        live_faces_(r.base.face_count()) {}

  /// Applies contractions while more than `target` faces are alive (simplify's stop test).
  void advance_to(std::size_t target) {
    while (live_faces_ > target && applied_ < r_.size()) apply(applied_++);
  }
  std::size_t applied() const { return applied_; }
  double max_error() const { return max_error_; }

  Mesh mesh() {
    const std::size_t nv = r_.base.vertex_count(), nf = r_.base.face_count();
    std::vector<std::uint32_t> remap(nv, kNone);
    Mesh out;
    out.indices.reserve(3 * live_faces_);
    for (std::size_t f = 0; f < nf; ++f) {
      if (face_dead_[f]) continue;
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = find(r_.base.indices[3 * f + k]);
        remap[v] = 0;  // used; numbered below
        out.indices.push_back(v);
      }
    }
    std::uint32_t next = 0;
    for (std::size_t v = 0; v < nv; ++v) {
      if (remap[v] == kNone) continue;
      remap[v] = next++;
      const double* p =
          last_move_[v] == kNone ? &r_.base.positions[3 * v] : &r_.position[3 * std::size_t(last_move_[v])];
      out.positions.insert(out.positions.end(), p, p + 3);
    }
    for (std::uint32_t& i : out.indices) i = remap[i];
    return out;
  }

 private:
  void apply(std::size_t i) {
    parent_[r_.removed[i]] = r_.kept[i];
    last_move_[r_.kept[i]] = std::uint32_t(i);
    max_error_ = std::max(max_error_, r_.error[i]);
    for (std::uint32_t k = r_.dead_begin[i]; k < r_.dead_begin[i + 1]; ++k) {
      face_dead_[r_.dead_faces[k]] = 1;
      --live_faces_;
    }
  }
  std::uint32_t find(std::uint32_t v) {
    std::uint32_t root = v;
    while (parent_[root] != kNone) root = parent_[root];
    while (parent_[v] != kNone) {  // path compression: later finds are O(1)
      const std::uint32_t up = parent_[v];
      parent_[v] = root;
      v = up;
    }
    return root;
  }

  const Record& r_;
  std::vector<std::uint32_t> parent_;     // removed vertex -> the vertex it merged into
  std::vector<std::uint32_t> last_move_;  // last contraction that placed the vertex, or kNone
  std::vector<std::uint8_t> face_dead_;
  std::size_t live_faces_;
  std::size_t applied_ = 0;
  double max_error_ = 0;
};

}  // namespace

Mesh replay(const Record& record, std::size_t target_faces) {
  validate_record(record);
  Replayer r(record);
  r.advance_to(target_faces);
  return r.mesh();
}

std::vector<ReplayLevel> replay_levels(const Record& record, std::span<const std::size_t> targets) {
  validate_record(record);
  // Finest level first: contractions only ever go forward.
  std::vector<std::size_t> order(targets.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return targets[a] > targets[b]; });
  std::vector<ReplayLevel> levels(targets.size());
  Replayer r(record);
  for (std::size_t i : order) {
    r.advance_to(targets[i]);
    levels[i].mesh = r.mesh();
    levels[i].target_faces = targets[i];
    levels[i].contractions = r.applied();
    levels[i].max_error = r.max_error();
  }
  return levels;
}

}  // namespace qem
