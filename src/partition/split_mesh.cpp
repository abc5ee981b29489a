// The cut of qem/partition.h: faces in Morton order of their centroids, cut into ranges of equal
// length (to within a percent). A range of a Morton curve is a compact region (a union of few octree cells), so its cut
// is short next to its area, and the cut needs no connectivity, only the face list.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <unordered_map>

#include "check_mesh.h"
#include "core/default_init_allocator.h"
#include "core/parallel_chunks.h"
#include "core/same_position.h"
#include "core/spatial_order.h"
#include "material_carrier.h"
#include "partition/partition_targets.h"
#include "qem/error.h"
#include "qem/partition.h"

namespace qem {

unsigned automatic_parts(std::size_t faces) {
  constexpr std::size_t kMinFaces = 1000000, kFacesPerPart = 500000;
  constexpr unsigned kMaxParts = 64;
  if (faces < kMinFaces) return 1;
  unsigned parts = 1;
  while (parts < kMaxParts && faces / (2 * std::size_t(parts)) >= kFacesPerPart) parts *= 2;
  return parts;
}

// The mesh no longer decides (its attributes and materials are carried); the signature keeps it for
// the callers, which ask about a mesh and its options together.
std::string partition_refusal(MeshView /*input*/, const SimplifyOptions& o) {
  if (std::isfinite(o.max_error))
    return "an error limit (--max-error) is measured against each part's quadrics, not the whole mesh's";
  if (std::isfinite(o.max_distance))
    return "a distance bound (--max-distance) is certified against the whole input, and the final pass "
           "would see only the parts' output";
  if (o.threshold > 0) return "a pair threshold (--threshold) would pair vertices across the cuts";
  if (o.prune_size > 0) return "pruning (--prune) judges whole components, which the cuts divide";
  if (o.as_far_as_possible) return "a target of 0 (as far as the checks allow) has no share to give each part";
  if (o.target_faces == 0 && o.target_ratio == 0 && o.target_vertices == 0)
    return "there is no face or vertex target to share among the parts";
  return {};
}

namespace partition_detail {

Targets resolve_targets(const SimplifyOptions& o, std::size_t faces) {
  Targets t;
  if (o.target_faces > 0) t.faces = o.target_faces;
  // As the core resolves a ratio (core/settings.cpp): of the faces left after dropping degenerate
  // ones (and, in finish_partitioned, duplicates), the larger face target winning when both are given.
  if (o.target_ratio > 0) t.faces = std::max(t.faces, std::size_t(std::floor(o.target_ratio * double(faces))));
  t.vertices = o.target_vertices;
  return t;
}

SimplifyOptions final_pass_options(const SimplifyOptions& options, const Targets& total) {
  SimplifyOptions o = options;
  o.target_faces = total.faces;
  o.target_ratio = 0;
  o.target_vertices = total.vertices;
  o.refit_rounds = 0;
  o.far_repair = false;
  o.fit_attributes = false;
  return o;
}

Targets part_targets(const Targets& total, std::size_t part_faces, std::size_t all_faces,
                     std::size_t part_vertices, std::size_t all_vertices, std::size_t locked,
                     double share_slack) {
  // The part's share of the target, in proportion to its faces (vertices), plus two per cut
  // vertex: the strip along the locked cut keeps faces that the final pass removes, and which must
  // not be taken out of the part's interior (it would end up coarser than the rest). With one per
  // cut vertex the final pass had too little left to undo the cut's strip: after the closed-form
  // placement and the input-normal guard landed, the bumpy sphere's Hausdorff distance in 4 parts
  // rose to 1.21x the in-core run's (Partition.ErrorStaysNearTheInCoreRun); with two it is within.
  // The share itself is `share_slack` times the part's proportion (kPartShareSlack in memory):
  // the final pass makes its quadrics afresh from the welded parts and, since the parts forget
  // (SimplifyOptions::forget), it needs room of its own to reach the in-core run's mean error.
  // At least 1 (0 means unused): a part whose share rounds to nothing goes as far as it can.
  Targets t;
  if (total.faces > 0)
    t.faces = std::max<std::size_t>(1, std::size_t(share_slack * double(total.faces) * double(part_faces) /
                                                   double(std::max<std::size_t>(1, all_faces))) +
                                           2 * locked);
  if (total.vertices > 0)
    t.vertices = std::max<std::size_t>(1, std::size_t(double(total.vertices) * double(part_vertices) /
                                                      double(std::max<std::size_t>(1, all_vertices))) +
                                              locked);
  return t;
}

}  // namespace partition_detail

namespace {

std::uint32_t point_of(const std::vector<std::uint32_t>& point, std::uint32_t v) { return point.empty() ? v : point[v]; }

constexpr std::uint32_t kNone = 0xffffffffu;
constexpr std::uint16_t kNoPart = 0xffff;
constexpr std::size_t kChunk = std::size_t(1) << 16;  // faces per chunk of the parallel loops
// The per-face and per-vertex arrays below are written whole on the threads and not zeroed first
// (UnzeroedVector), so that their fresh pages are touched on the threads, not in a serial stretch.
template <class T>
using Array = core::UnzeroedVector<T>;
// Sets every element of `a` to `value`, on the threads.
template <class T, class V>
void fill_on_threads(T& a, const V& value, unsigned threads) {
  core::for_chunks(a.size(), kChunk, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) a[i] = value;
  });
}

// The Morton code of each face's centroid over the input's bounding box (21 bits per axis, as the
// core's vertex order), UINT64_MAX for a degenerate face (a repeated corner: no plane, left out as
// the core leaves it out). `point`: each vertex's point of the surface (itself, or with attributes
// the first vertex at its position: two wedges of one position make a face degenerate in the core;
// empty: each vertex is its own point).
Array<std::uint64_t> centroid_codes(MeshView input, const std::vector<std::uint32_t>& point, unsigned threads) {
  const Box box = bounding_box(input);
  const double extent = std::max({box.hi[0] - box.lo[0], box.hi[1] - box.lo[1], box.hi[2] - box.lo[2]});
  const double scale = extent > 0 ? double((1 << 21) - 1) / extent : 0;
  Array<std::uint64_t> code(input.face_count());
  core::for_chunks(code.size(), kChunk, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) {
      const std::uint32_t* t = &input.indices[3 * f];
      const std::uint32_t x = point_of(point, t[0]), y = point_of(point, t[1]), z = point_of(point, t[2]);
      if (x == y || y == z || x == z) {
        code[f] = UINT64_MAX;
        continue;
      }
      double centroid[3];
      for (int k = 0; k < 3; ++k)
        centroid[k] =
            (input.positions[3 * std::size_t(t[0]) + k] + input.positions[3 * std::size_t(t[1]) + k] +
             input.positions[3 * std::size_t(t[2]) + k]) /
            3;
      code[f] = core::morton_code(centroid, box.lo, scale);
    }
  });
  return code;
}

}  // namespace

std::vector<MeshPart> split_mesh(MeshView input, const SimplifyOptions& options, unsigned part_count,
                                 PartitionReport* report) {
  if (needs_material_carrier(input)) {  // taken off by finish_partitioned (material_carrier.h)
    return with_material_carrier(
        input, [&](MeshView with) { return split_mesh(with, options, part_count, report); });
  }
  check_mesh(input, "input");
  if (const std::string why = partition_refusal(input, options); !why.empty())
    throw Error("cannot simplify part by part: " + why);
  if (!options.vertex_lock.empty() && options.vertex_lock.size() != input.vertex_count())
    throw Error("vertex_lock has " + std::to_string(options.vertex_lock.size()) + " entries for " +
                std::to_string(input.vertex_count()) + " vertices");
  if (!options.vertex_protect.empty() && options.vertex_protect.size() != input.vertex_count())
    throw Error("vertex_protect has " + std::to_string(options.vertex_protect.size()) + " entries for " +
                std::to_string(input.vertex_count()) + " vertices");
  if (part_count > kNoPart) throw Error("at most " + std::to_string(kNoPart) + " parts");
  part_count = std::max(1u, part_count);
  const unsigned threads = core::resolve_threads(options.threads);
  const std::size_t nf = input.face_count();
  // With attributes the core welds the wedges of a position into one point of the surface, and so
  // does the cut: a seam that crosses it (wedge a on one side's faces, wedge b on the other's, the
  // same position) has no vertex index that two parts share, and found by index neither wedge
  // would be locked, each part would move its own, and the seam would open into a crack.
  const std::vector<std::uint32_t> point =
      input.attributes.empty() ? std::vector<std::uint32_t>{} : core::first_at_same_position(input, threads);
  const Array<std::uint64_t> code = centroid_codes(input, point, threads);

  // The cut: P-quantiles of the codes, taken from a sample of every k-th face (deterministic), so
  // that no serial sort of all faces is needed; parts then hold equal face counts to within about
  // a percent. A face goes to the part whose code range holds its code.
  std::vector<std::uint64_t> sample;
  const std::size_t stride = std::max<std::size_t>(1, nf / (std::size_t(part_count) * 16384));
  for (std::size_t f = 0; f < nf; f += stride)
    if (code[f] != UINT64_MAX) sample.push_back(code[f]);
  std::sort(sample.begin(), sample.end());
  part_count = unsigned(std::min<std::size_t>(part_count, std::max<std::size_t>(1, sample.size())));
  std::vector<std::uint64_t> splitter;
  for (unsigned p = 1; p < part_count; ++p) splitter.push_back(sample[sample.size() * p / part_count]);
  const std::size_t chunks = (nf + kChunk - 1) / kChunk;
  Array<std::uint16_t> part_of(nf);
  std::vector<std::vector<std::uint32_t>> count(chunks, std::vector<std::uint32_t>(part_count, 0));
  core::for_chunks(nf, kChunk, threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) {
      if (code[f] == UINT64_MAX) {
        part_of[f] = kNoPart;
        continue;
      }
      part_of[f] = std::uint16_t(std::upper_bound(splitter.begin(), splitter.end(), code[f]) - splitter.begin());
      ++count[c][part_of[f]];
    }
  });
  // Each part's faces in input order: chunk c writes from the sum of the earlier chunks' counts.
  std::vector<std::size_t> part_begin(part_count + 1, 0);
  std::vector<std::vector<std::size_t>> at(chunks, std::vector<std::size_t>(part_count, 0));
  for (unsigned p = 0; p < part_count; ++p) {
    std::size_t next = part_begin[p];
    for (std::size_t c = 0; c < chunks; ++c) at[c][p] = next, next += count[c][p];
    part_begin[p + 1] = next;
  }
  const std::size_t n = part_begin[part_count];  // the non-degenerate faces
  Array<std::uint32_t> faces(n);
  core::for_chunks(nf, kChunk, threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f)
      if (part_of[f] != kNoPart) faces[at[c][part_of[f]]++] = std::uint32_t(f);
  });

  // A vertex is on a cut when faces of two parts use it (with attributes: its position; then every
  // wedge there is on the cut, in each part that has it): the first part to claim it (whichever
  // thread is first) finds no owner, any other part finds one that is not itself. Which part
  // claims first varies; whether a second one exists does not, so `shared` is deterministic.
  // (Plain arrays, taken atomically where the parts meet: std::atomic elements would be zeroed by
  // their constructors, serially.)
  Array<std::uint32_t> owner(input.vertex_count());
  fill_on_threads(owner, kNone, threads);
  Array<std::uint8_t> shared_flag(input.vertex_count());
  fill_on_threads(shared_flag, std::uint8_t(0), threads);
  core::for_chunks(part_count, 1, threads, [&](std::size_t p, std::size_t, std::size_t) {
    for (std::size_t i = part_begin[p]; i < part_begin[p + 1]; ++i)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = point_of(point, input.indices[3 * std::size_t(faces[i]) + k]);
        std::uint32_t expected = kNone;
        if (!std::atomic_ref(owner[v]).compare_exchange_strong(expected, std::uint32_t(p), std::memory_order_relaxed) &&
            expected != p)
          std::atomic_ref(shared_flag[v]).store(1, std::memory_order_relaxed);
      }
  });
  std::vector<std::uint8_t> shared(input.vertex_count());
  std::size_t referenced = 0;
  for (std::size_t v = 0; v < shared.size(); ++v) {
    shared[v] = shared_flag[point_of(point, std::uint32_t(v))];  // after the threads: no atomics needed
    referenced += owner[v] != kNone;
  }
  Array<std::uint8_t>().swap(shared_flag);
  Array<std::uint32_t>().swap(owner);

  const partition_detail::Targets total = partition_detail::resolve_targets(options, n);
  std::vector<MeshPart> parts(part_count);
  // Part vertices numbered in order of first use along the part's faces. A vertex only one part
  // uses is numbered in one shared array (no other part writes it); a shared one in the part's map.
  Array<std::uint32_t> local(input.vertex_count());
  fill_on_threads(local, kNone, threads);
  core::for_chunks(part_count, 1, threads, [&](std::size_t p, std::size_t, std::size_t) {
    MeshPart& part = parts[p];
    std::unordered_map<std::uint32_t, std::uint32_t> shared_local;
    const std::size_t begin = part_begin[p], end = part_begin[p + 1];
    part.mesh.indices.reserve(3 * (end - begin));
    part.input_face.reserve(end - begin);
    // Room for the vertices of a closed manifold part (half as many as its faces) and a cut of a
    // sixteenth more, so that the arrays are not grown by copying into fresh pages as they fill:
    // without it, those copies and their page faults were about half the page faults of a 10M-face
    // run (perf record -e page-faults), on the threads and on the calling thread alike. A part
    // with more vertices still grows its arrays, from there.
    const std::size_t vertices_guess = (end - begin) / 2 + (end - begin) / 16 + 64;
    part.mesh.positions.reserve(3 * vertices_guess);
    part.input_vertex.reserve(vertices_guess);
    part.locked.reserve(vertices_guess);
    // The attribute rows of the part's vertices and the materials of its faces (the names stay the
    // input's: face_materials index them), the caller's protection in the part's numbering.
    for (const VertexAttribute& a : input.attributes) {
      part.mesh.attributes.push_back({a.name, a.kind, a.components, {}});
      part.mesh.attributes.back().values.reserve(a.components * vertices_guess);
    }
    if (!input.face_materials.empty()) part.mesh.face_materials.reserve(end - begin);
    if (!options.vertex_protect.empty()) part.protect.reserve(vertices_guess);
    std::size_t locked_count = 0;
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t f = faces[i];
      part.input_face.push_back(f);
      if (!input.face_materials.empty()) part.mesh.face_materials.push_back(input.face_materials[f]);
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = input.indices[3 * std::size_t(f) + k];
        std::uint32_t* id = nullptr;
        if (shared[v]) id = &shared_local.try_emplace(v, kNone).first->second;
        else id = &local[v];
        if (*id == kNone) {
          *id = std::uint32_t(part.input_vertex.size());
          part.input_vertex.push_back(v);
          part.mesh.positions.insert(part.mesh.positions.end(), &input.positions[3 * std::size_t(v)],
                                     &input.positions[3 * std::size_t(v)] + 3);
          const bool lock = shared[v] || (!options.vertex_lock.empty() && options.vertex_lock[v]);
          part.locked.push_back(lock);
          locked_count += shared[v];
          for (std::size_t a = 0; a < input.attributes.size(); ++a) {
            const std::size_t width = input.attributes[a].components;
            const double* row = &input.attributes[a].values[width * v];
            part.mesh.attributes[a].values.insert(part.mesh.attributes[a].values.end(), row, row + width);
          }
          if (!options.vertex_protect.empty()) part.protect.push_back(options.vertex_protect[v]);
        }
        part.mesh.indices.push_back(*id);
      }
    }
    const partition_detail::Targets mine =
        partition_detail::part_targets(total, end - begin, n, part.input_vertex.size(), referenced,
                                       locked_count, partition_detail::kPartShareSlack);
    part.target_faces = mine.faces, part.target_vertices = mine.vertices;
  });
  if (report) {
    report->parts = part_count;
    report->shared_vertices = std::size_t(std::count(shared.begin(), shared.end(), 1));
  }
  return parts;
}

}  // namespace qem
