// The cut of qem/partition.h: faces in Morton order of their centroids, cut into ranges of equal
// length. A range of a Morton curve is a compact region (a union of few octree cells), so its cut
// is short next to its area, and the cut needs no connectivity, only the face list.
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "check_mesh.h"
#include "core/parallel_chunks.h"
#include "core/spatial_order.h"
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

std::string partition_refusal(MeshView input, const SimplifyOptions& o) {
  if (!input.attributes.empty())
    return "the mesh has vertex attributes (normals, UVs, colours), which the parts do not carry";
  if (!input.face_materials.empty()) return "the mesh has face materials, which the parts do not carry";
  if (std::isfinite(o.max_error))
    return "an error limit (--max-error) is measured against each part's quadrics, not the whole mesh's";
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
  // ones, the larger face target winning when both are given.
  if (o.target_ratio > 0) t.faces = std::max(t.faces, std::size_t(std::floor(o.target_ratio * double(faces))));
  t.vertices = o.target_vertices;
  return t;
}

}  // namespace partition_detail

std::vector<MeshPart> split_mesh(MeshView input, const SimplifyOptions& options, unsigned part_count,
                                 PartitionReport* report) {
  check_mesh(input, "input");
  if (const std::string why = partition_refusal(input, options); !why.empty())
    throw Error("cannot simplify part by part: " + why);
  if (!options.vertex_lock.empty() && options.vertex_lock.size() != input.vertex_count())
    throw Error("vertex_lock has " + std::to_string(options.vertex_lock.size()) + " entries for " +
                std::to_string(input.vertex_count()) + " vertices");
  part_count = std::max(1u, part_count);
  // Degenerate faces (a repeated corner) carry no plane: left out, as the core leaves them out.
  std::vector<std::uint32_t> faces;
  faces.reserve(input.face_count());
  for (std::uint32_t f = 0; f < input.face_count(); ++f) {
    const std::uint32_t* t = &input.indices[3 * std::size_t(f)];
    if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) faces.push_back(f);
  }
  const std::size_t n = faces.size();
  part_count = unsigned(std::min<std::size_t>(part_count, std::max<std::size_t>(1, n)));
  const std::vector<std::uint32_t> order = core::morton_order(n, [&](std::size_t i) {
    const std::uint32_t* t = &input.indices[3 * std::size_t(faces[i])];
    Vec3 c{0, 0, 0};
    for (int k = 0; k < 3; ++k)
      c = c + Vec3(input.positions[3 * std::size_t(t[k])], input.positions[3 * std::size_t(t[k]) + 1],
                         input.positions[3 * std::size_t(t[k]) + 2]);
    return c * (1.0 / 3);
  });
  const auto range_begin = [&](unsigned p) { return n * p / part_count; };

  // Each vertex's first part (in part order) and whether another part uses it too.
  constexpr std::uint32_t kNone = 0xffffffffu;
  std::vector<std::uint32_t> owner(input.vertex_count(), kNone);
  std::vector<std::uint8_t> shared(input.vertex_count(), 0);
  for (unsigned p = 0; p < part_count; ++p)
    for (std::size_t i = range_begin(p); i < range_begin(p + 1); ++i)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = input.indices[3 * std::size_t(faces[order[i]]) + k];
        if (owner[v] == kNone) owner[v] = p;
        else if (owner[v] != p) shared[v] = 1;
      }

  const partition_detail::Targets total = partition_detail::resolve_targets(options, n);
  std::size_t referenced = 0;
  for (std::uint32_t o : owner) referenced += o != kNone;
  std::vector<MeshPart> parts(part_count);
  // Part vertices numbered in order of first use along the part's faces. A vertex only its owner
  // uses is numbered in one shared array (no other part writes it); a shared one in the part's map.
  std::vector<std::uint32_t> local(input.vertex_count(), kNone);
  core::for_chunks(part_count, 1, core::resolve_threads(options.threads), [&](std::size_t p, std::size_t, std::size_t) {
    MeshPart& part = parts[p];
    std::unordered_map<std::uint32_t, std::uint32_t> shared_local;
    const std::size_t begin = range_begin(unsigned(p)), end = range_begin(unsigned(p) + 1);
    part.mesh.indices.reserve(3 * (end - begin));
    part.input_face.reserve(end - begin);
    std::size_t locked_count = 0;
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t f = faces[order[i]];
      part.input_face.push_back(f);
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
        }
        part.mesh.indices.push_back(*id);
      }
    }
    // The part's share of the target, in proportion to its faces (vertices), plus its cut
    // vertices: each keeps about one face of the strip along the cut, which the final pass removes,
    // and which must not be taken out of the part's interior (it would end up coarser than the rest).
    const std::size_t part_faces = end - begin, part_vertices = part.input_vertex.size();
    if (total.faces > 0)
      part.target_faces = std::size_t(double(total.faces) * double(part_faces) / double(std::max<std::size_t>(1, n))) +
                          locked_count;
    if (total.vertices > 0)
      part.target_vertices =
          std::size_t(double(total.vertices) * double(part_vertices) / double(std::max<std::size_t>(1, referenced))) +
          locked_count;
  });
  if (report) {
    report->parts = part_count;
    report->shared_vertices = std::size_t(std::count(shared.begin(), shared.end(), 1));
  }
  return parts;
}

}  // namespace qem
