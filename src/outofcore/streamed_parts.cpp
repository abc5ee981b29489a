#include "outofcore/streamed_parts.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>
#include <unordered_map>
#include <vector>

#include "core/distance_bound.h"
#include "core/far_repair.h"
#include "core/parallel_chunks.h"
#include "core/release_memory.h"
#include "core/spatial_order.h"
#include "outofcore/mesh_stream.h"
#include "outofcore/temp_file.h"
#include "partition/partition_targets.h"
#include "qem/error.h"
#include "qem/partition.h"
#include "refit/refit_after_simplify.h"
#include "refit/refit_points.h"

namespace qem::outofcore {

namespace {

/// Beyond this many budgets of input, clustering: by parts, every face is contracted (an in-core
/// run's time), and an input that large gives clustering's phase 2 tens of times the target at the
/// targets people ask of it (the billion-face torus to a million: 5.9x under 2G, 26x by default).
constexpr double kMaxBudgets = 8;
constexpr unsigned kMaxParts = 64;
/// A part being simplified: the in-core run's peak, and the part's own copy (positions as doubles,
/// faces, the maps to the input, the records read back).
constexpr double kPartBytesPerFace = kInCoreBytesPerFace + 64;
/// What one part's output takes until it is welded (mesh, sources), per face.
constexpr double kOutputBytesPerFace = 100;
/// Rings of faces along a cut that the refit by parts holds (refit_by_parts).
constexpr int kCutRings = 2;
/// A part's share of the target over its proportion (partition_detail::part_targets), larger than
/// the in-memory run's: the final pass has more to choose from, and here the refit goes part by
/// part with the cuts' bands held. Over the four rows of docs/benchmarks.md's "By parts" (to 10 %),
/// E / in-core 0.99-1.02x and Hausdorff 0.83-1.10x, against 0.99-1.10x and 1.04-1.08x with 1.25x;
/// with 2x the 10M torus's Hausdorff rose to 1.22x. Where the final pass would not fit the budget
/// with it, the in-memory run's share.
constexpr double kShareSlack = 1.6;
/// Faces a part gathers in memory before they go to the file: 256 KB a part.
constexpr std::size_t kBlockFaces = 16384;

/// A face on disk: its corners (input vertices) and its index in the input.
struct FaceRecord {
  std::uint32_t corner[3];
  std::uint32_t face;
};

/// The cut vertices of `parts` Morton ranges of `faces` faces: about the ranges' perimeters (a
/// range is a compact region of the surface, with about sqrt of its faces on each side), with a margin.
double estimated_cut_vertices(double faces, unsigned parts) { return 4 * std::sqrt(faces * parts); }

/// The Morton code of a face's centroid (21 bits an axis over the bounding box), as split_mesh's.
std::uint64_t centroid_code(const PositionSource& positions, const std::uint32_t* t, const double lo[3],
                            double scale) {
  double p[3][3], centroid[3];
  for (int k = 0; k < 3; ++k) positions.get(t[k], p[k]);
  for (int a = 0; a < 3; ++a) centroid[a] = (p[0][a] + p[1][a] + p[2][a]) / 3;
  return core::morton_code(centroid, lo, scale);
}

bool degenerate(const std::uint32_t* t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

/// One simplified part in the input's numbering: its output and, per output vertex, the input
/// vertex it started as and whether it is on a cut (then it never moved and is welded by index).
struct PartOutput {
  Mesh mesh;
  std::vector<std::uint32_t> input_vertex;
  std::vector<std::uint8_t> cut;
  std::size_t contractions = 0;
  double max_error = 0;
};

/// The corners of the faces `indices` of `mesh`, 9 doubles a face (core::SurfaceDistance's form).
std::vector<double> corners_of(const Mesh& mesh, const std::vector<std::uint32_t>& indices) {
  std::vector<double> corners(3 * indices.size());
  for (std::size_t i = 0; i < indices.size(); ++i)
    for (int a = 0; a < 3; ++a) corners[3 * i + a] = mesh.positions[3 * std::size_t(indices[i]) + a];
  return corners;
}

/// The far-place repair (core/far_repair.h) of one part's refitted faces against its input, the
/// `held` vertices (near the cuts) kept with their edges; no relocation at a border (the part's
/// faces end at the held band, whose edges are no border of the output). True when it changed the
/// faces; a repair that changed the part's outline (it never should: the outline's vertices are
/// held) is undone, the refitted faces kept.
bool repair_part(Mesh& sub, const std::vector<std::uint8_t>& held, const Mesh& input,
                 const refit_detail::FitPoints& points, const core::SurfaceDistance& surface,
                 const std::vector<std::uint32_t>& closest, const SimplifyOptions& options) {
  const auto outline = [](const Mesh& m) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (std::size_t i = 0; i < m.indices.size(); i += 3)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = m.indices[i + k], b = m.indices[i + (k + 1) % 3];
        edges.emplace_back(std::min(a, b), std::max(a, b));
      }
    std::sort(edges.begin(), edges.end());
    std::vector<std::pair<std::uint32_t, std::uint32_t>> once;
    for (std::size_t i = 0; i < edges.size();) {
      std::size_t j = i;
      while (j < edges.size() && edges[j] == edges[i]) ++j;
      if (j - i == 1) once.push_back(edges[i]);
      i = j;
    }
    return once;
  };
  const Mesh refitted = sub;
  SimplifyOptions one = options;
  one.threads = 1;
  const std::vector<std::uint8_t> no_border(points.weight.size(), 0);
  const core::FarRepairResult made = repair_mesh(sub, one, input, no_border, points, surface, held, closest);
  if (made.relocations.empty() && made.flips == 0) return false;
  if (outline(sub) != outline(refitted)) {
    sub = refitted;
    return false;
  }
  return true;
}

/// The refit of the output (simplify's, Hoppe et al. 1993) against the input part by part, each
/// part's input faces read back from disk: each output face goes to the part whose output it came
/// from (`face_source` into the welded parts, part p's faces ending at `part_end[p]`; a face's own
/// centroid can fall in another part's code range where a cell wall runs along the surface, with
/// none of that part's input under it), and the output vertices of one part's faces only are
/// fitted to that part's input vertices (area-weighted, thinned as an in-core run's) with the guard
/// on that part's input surface, then repaired against it (`options.far_repair`). Near the cuts
/// the output stays as the final pass left it (below), so the parts move disjoint vertices and may
/// run side by side; the vertices and faces are put back after, in part order (docs/out-of-core.md,
/// "By parts").
template <class ReadPart>
void refit_by_parts(Mesh& out, const std::vector<std::uint32_t>& face_source,
                    const std::vector<std::uint64_t>& part_end, const SimplifyOptions& options,
                    unsigned concurrent, const ReadPart& read_part) {
  const unsigned parts = unsigned(part_end.size());
  const std::size_t nf = out.face_count(), nv = out.vertex_count();
  std::vector<std::uint16_t> part_of(nf), owner(nv, std::uint16_t(0xffff));
  std::vector<std::uint8_t> fixed(nv, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t* t = &out.indices[3 * f];
    part_of[f] = std::uint16_t(
        std::upper_bound(part_end.begin(), part_end.end(), std::uint64_t(face_source[f])) - part_end.begin());
    for (int k = 0; k < 3; ++k) {
      if (owner[t[k]] == 0xffff)
        owner[t[k]] = part_of[f];
      else if (owner[t[k]] != part_of[f])
        fixed[t[k]] = 1;
    }
  }
  // Near a cut (within kCutRings rings of a vertex of two parts' faces) the vertices are held and
  // the faces with no other vertex left out: each part's guard measures the distance to that
  // part's input alone, which near the cut lacks the other side's faces, and such a face's distance
  // would raise the bound the guard keeps every move within (by 1.4x on the generated sphere's
  // part at one ring; docs/out-of-core.md, "By parts").
  std::vector<std::uint8_t> near_cut = fixed;  // grown by kCutRings rings of faces
  for (int ring = 0; ring < kCutRings; ++ring) {
    std::vector<std::uint8_t> grown = near_cut;
    for (std::size_t f = 0; f < nf; ++f) {
      const std::uint32_t* t = &out.indices[3 * f];
      if (near_cut[t[0]] || near_cut[t[1]] || near_cut[t[2]]) grown[t[0]] = grown[t[1]] = grown[t[2]] = 1;
    }
    near_cut.swap(grown);
  }
  const std::vector<std::uint8_t>& held = near_cut;
  std::vector<std::vector<std::uint32_t>> faces_of(parts);
  std::vector<std::uint32_t>
      left_out;  // the faces left out, as a surface: which input points are theirs (below)
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t* t = &out.indices[3 * f];
    if (near_cut[t[0]] && near_cut[t[1]] && near_cut[t[2]])
      left_out.insert(left_out.end(), t, t + 3);
    else
      faces_of[part_of[f]].push_back(std::uint32_t(f));
  }
  const core::SurfaceDistance band =
      left_out.empty() ? core::SurfaceDistance() : core::SurfaceDistance(corners_of(out, left_out));
  // Each part's faces refitted, and repaired, on their own; the vertices and faces put back after.
  struct Fitted {
    Mesh sub;                           // the part's faces, as refitted (and repaired)
    std::vector<std::uint32_t> global;  // per sub vertex before the repair: its output vertex
    bool repaired = false;              // the repair changed the faces
  };
  std::vector<Fitted> fitted(parts);
  core::for_chunks(parts, 1, concurrent, [&](std::size_t p, std::size_t, std::size_t) {
    if (faces_of[p].empty()) return;
    Mesh input;
    std::vector<std::uint32_t> input_vertex;
    read_part(p, input, input_vertex, nullptr);
    // The part's output faces, their vertices numbered in order of first use.
    Mesh& sub = fitted[p].sub;
    std::vector<std::uint32_t>& global = fitted[p].global;
    std::unordered_map<std::uint32_t, std::uint32_t> local;
    std::vector<std::uint8_t> sub_held;
    for (std::uint32_t f : faces_of[p])
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = out.indices[3 * std::size_t(f) + k];
        const auto [it, fresh] = local.try_emplace(v, std::uint32_t(global.size()));
        if (fresh) {
          global.push_back(v);
          sub.positions.insert(sub.positions.end(), &out.positions[3 * std::size_t(v)],
                               &out.positions[3 * std::size_t(v)] + 3);
          sub_held.push_back(held[v]);
        }
        sub.indices.push_back(it->second);
      }
    RefitOptions refit = refit_options_for(options, input_vertex.size(), global.size());
    if (refit.rounds == 0) return;
    refit.threads = 1;
    refit.fixed_vertices = sub_held;
    // The input points nearer the faces left out than the part's own are theirs: left out too, or
    // they would pull the part's faces toward the cut, and the repair would find its farthest
    // places under faces it may not change.
    std::vector<double> weights = refit_detail::vertex_areas(input);
    if (!band.empty()) {
      const core::SurfaceDistance own(corners_of(sub, sub.indices));
      std::uint32_t hint_band = UINT32_MAX, hint_own = UINT32_MAX;
      for (std::size_t v = 0; v < weights.size(); ++v) {
        const Vec3 q{input.positions[3 * v], input.positions[3 * v + 1], input.positions[3 * v + 2]};
        if (band.distance(q, &hint_band) < own.distance(q, &hint_own)) weights[v] = 0;
      }
    }
    const refit_detail::FitPoints points(input.positions, weights, 1);
    const core::SurfaceDistance surface =
        refit_detail::surface_in_frame(input.positions, input.indices, points.frame(), 1);
    std::vector<std::uint32_t> closest;
    refit_detail::refit_to_points(points, sub, refit, {}, &surface, options.far_repair ? &closest : nullptr);
    if (options.far_repair)
      fitted[p].repaired = repair_part(sub, sub_held, input, points, surface, closest, options);
  });
  // Put back: positions of the vertices that could move; where a part's repair changed its faces,
  // the faces near the cuts and then each part's faces in turn, its new vertices appended.
  bool any_repaired = false;
  for (const Fitted& f : fitted) any_repaired |= f.repaired;
  std::vector<std::uint32_t> indices;
  if (any_repaired)
    for (std::size_t f = 0; f < nf; ++f) {
      const std::uint32_t* t = &out.indices[3 * f];
      if (near_cut[t[0]] && near_cut[t[1]] && near_cut[t[2]]) indices.insert(indices.end(), t, t + 3);
    }
  for (std::size_t p = 0; p < parts; ++p) {
    Fitted& f = fitted[p];
    std::vector<std::uint32_t> to_out = f.global;
    for (std::size_t l = f.global.size(); l < f.sub.vertex_count(); ++l) {  // vertices a repair added
      to_out.push_back(std::uint32_t(out.vertex_count()));
      out.positions.insert(out.positions.end(), &f.sub.positions[3 * l], &f.sub.positions[3 * l] + 3);
    }
    for (std::size_t l = 0; l < f.global.size(); ++l)
      if (!held[f.global[l]])
        for (int a = 0; a < 3; ++a)
          out.positions[3 * std::size_t(f.global[l]) + a] = f.sub.positions[3 * l + a];
    if (!any_repaired) continue;
    for (std::uint32_t v : f.sub.indices) indices.push_back(to_out[v]);
    f = Fitted{};
  }
  if (any_repaired) out.indices = std::move(indices);
}

}  // namespace

StreamedPartsPlan plan_streamed_parts(std::uint64_t faces, std::uint64_t vertices, std::size_t target_faces,
                                      double budget, double resident, unsigned threads) {
  if (target_faces == 0 || kInCoreBytesPerFace * double(faces) > kMaxBudgets * budget) return {};
  for (unsigned parts = 2; parts <= kMaxParts; parts *= 2) {
    const double part_faces =
        1.02 * double(faces) / parts;  // the cut's sample: equal within a percent or two
    // The fewest parts, and for them the larger share that fits (kShareSlack, else the in-memory
    // run's).
    for (const double slack : {kShareSlack, partition_detail::kPartShareSlack}) {
      const double merged = slack * double(target_faces) + 2 * estimated_cut_vertices(double(faces), parts);
      const double fixed = resident + 5.0 * double(vertices) + parts * kBlockFaces * sizeof(FaceRecord) +
                           kOutputBytesPerFace * merged;
      const double room = budget - fixed;
      if (room < kPartBytesPerFace * part_faces) continue;
      if (kInCoreBytesPerFace * merged + resident + double(vertices) > budget) continue;  // the final pass
      const unsigned concurrent = unsigned(std::clamp(std::floor(room / (kPartBytesPerFace * part_faces)),
                                                      1.0, double(std::max(1u, threads))));
      return {parts, std::min(concurrent, parts), slack};
    }
  }
  return {};
}

bool simplify_streamed_parts(const std::string& path, const PositionSource& positions, const double lo[3],
                             double extent, const SimplifyOptions& options, const StreamedPartsPlan& plan,
                             const std::string& temp_dir, const std::function<void(double)>& progress,
                             SimplifyResult& result, StreamedPartsReport* report) {
  if (plan.parts < 2) throw Error("simplify_streamed_parts: at least two parts");
  const double scale = extent > 0 ? double((1 << 21) - 1) / extent : 0;
  const std::thread::id caller = std::this_thread::get_id();

  // The cut: the parts' boundaries are quantiles of a sample of the codes (every k-th face, so
  // the same on every run), as split_mesh takes them.
  std::vector<std::uint64_t> splitter;
  std::uint64_t vertex_count = 0;
  {
    MeshStream in(path);
    vertex_count = in.vertex_count();
    const std::uint64_t stride =
        std::max<std::uint64_t>(1, in.face_count() / (std::uint64_t(plan.parts) * 16384));
    std::vector<std::uint64_t> sample;
    std::uint64_t face = 0;
    in.read_triangles([&](const std::uint32_t* tri, std::size_t n) {
      for (std::size_t i = 0; i < n; ++i, ++face)
        if (face % stride == 0 && !degenerate(tri + 3 * i))
          sample.push_back(centroid_code(positions, tri + 3 * i, lo, scale));
      progress(0.05 * double(in.bytes_read()) / double(in.file_size()));
    });
    std::sort(sample.begin(), sample.end());
    if (sample.empty()) throw Error(path + ": no faces to simplify");
    for (unsigned p = 1; p < plan.parts; ++p) splitter.push_back(sample[sample.size() * p / plan.parts]);
  }
  const unsigned parts = plan.parts;

  // Each face to its part's blocks in the file; a vertex that faces of two parts use is on a cut.
  TempFile file(temp_dir, "parts");
  std::vector<std::vector<FaceRecord>> pending(parts);
  std::vector<std::vector<std::uint64_t>> blocks(parts);  // each part's full blocks: their offsets in bytes
  std::vector<std::uint64_t> part_faces(parts, 0);
  std::vector<std::uint8_t> shared(vertex_count, 0);
  {
    std::vector<std::uint16_t> owner(vertex_count, std::uint16_t(0xffff));
    MeshStream in(path);
    std::uint32_t face = 0;
    std::uint64_t offset = 0;
    in.read_triangles([&](const std::uint32_t* tri, std::size_t n) {
      for (std::size_t i = 0; i < n; ++i, ++face) {
        const std::uint32_t* t = tri + 3 * i;
        if (degenerate(t)) continue;  // no plane: the core leaves it out, as split_mesh does
        const auto p = std::uint16_t(
            std::upper_bound(splitter.begin(), splitter.end(), centroid_code(positions, t, lo, scale)) -
            splitter.begin());
        for (int k = 0; k < 3; ++k) {
          if (owner[t[k]] == 0xffff)
            owner[t[k]] = p;
          else if (owner[t[k]] != p)
            shared[t[k]] = 1;
        }
        pending[p].push_back({{t[0], t[1], t[2]}, face});
        ++part_faces[p];
        if (pending[p].size() == kBlockFaces) {
          file.write(pending[p].data(), kBlockFaces * sizeof(FaceRecord));
          blocks[p].push_back(offset);
          offset += kBlockFaces * sizeof(FaceRecord);
          pending[p].clear();
        }
      }
      progress(0.05 + 0.1 * double(in.bytes_read()) / double(in.file_size()));
    });
    file.rewind_for_reading();
  }
  std::uint64_t all_faces = 0, cut_vertices = 0;
  for (std::uint64_t f : part_faces) all_faces += f;
  for (std::uint8_t s : shared) cut_vertices += s;
  const partition_detail::Targets total = partition_detail::resolve_targets(options, all_faces);

  // Part p's input faces read back: its vertices (input indices, ascending), their positions and
  // the faces in that numbering, and (optional) each face's index in the input.
  const auto read_part = [&](std::size_t p, Mesh& mesh, std::vector<std::uint32_t>& vertices,
                             std::vector<std::uint32_t>* input_face) {
    std::vector<FaceRecord> records(part_faces[p]);
    std::size_t at = 0;
    for (std::uint64_t offset : blocks[p]) {
      file.read_at(offset, &records[at], kBlockFaces * sizeof(FaceRecord));
      at += kBlockFaces;
    }
    std::copy(pending[p].begin(), pending[p].end(), records.begin() + std::ptrdiff_t(at));
    vertices.reserve(3 * records.size());
    for (const FaceRecord& r : records) vertices.insert(vertices.end(), r.corner, r.corner + 3);
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    vertices.shrink_to_fit();
    mesh.positions.resize(3 * vertices.size());
    for (std::size_t l = 0; l < vertices.size(); ++l) positions.get(vertices[l], &mesh.positions[3 * l]);
    mesh.indices.reserve(3 * records.size());
    if (input_face) input_face->reserve(records.size());
    for (const FaceRecord& r : records) {
      for (int k = 0; k < 3; ++k)
        mesh.indices.push_back(std::uint32_t(std::lower_bound(vertices.begin(), vertices.end(), r.corner[k]) -
                                             vertices.begin()));
      if (input_face) input_face->push_back(r.face);
    }
  };

  // The parts: read back, simplified with their cuts locked, `plan.concurrent` at once.
  std::vector<PartOutput> outputs(parts);
  SimplifyOptions one = options;
  one.threads = 1;
  std::atomic<unsigned> done{0};
  std::atomic<bool> duplicates{false};
  core::for_chunks(parts, 1, plan.concurrent, [&](std::size_t p, std::size_t, std::size_t) {
    MeshPart part;
    read_part(p, part.mesh, part.input_vertex, &part.input_face);
    const std::vector<std::uint32_t>& vertices = part.input_vertex;
    part.locked.resize(vertices.size());
    std::size_t locked = 0;
    for (std::size_t l = 0; l < vertices.size(); ++l) {
      part.locked[l] = shared[vertices[l]];
      locked += part.locked[l];
    }
    const partition_detail::Targets mine = partition_detail::part_targets(
        total, part_faces[p], all_faces, vertices.size(), vertex_count, locked, plan.share_slack);
    part.target_faces = mine.faces, part.target_vertices = mine.vertices;
    MeshPartResult r = simplify_part(part, one);
    if (r.dropped_duplicate_faces > 0) duplicates = true;
    PartOutput& out = outputs[p];
    out.input_vertex.resize(r.mesh.vertex_count());
    out.cut.resize(r.mesh.vertex_count());
    for (std::size_t u = 0; u < r.mesh.vertex_count(); ++u) {
      out.input_vertex[u] = vertices[r.vertex_source[u]];
      out.cut[u] = part.locked[r.vertex_source[u]];
    }
    out.mesh = std::move(r.mesh);
    out.contractions = r.contractions;
    out.max_error = r.max_error;
    const unsigned d = ++done;
    if (std::this_thread::get_id() == caller) progress(0.15 + 0.6 * double(d) / double(parts));
  });
  std::vector<std::uint8_t>().swap(shared);
  // Duplicate faces may be the reversed copies that make a sheet two-sided, which a whole run puts
  // back along the rims (SimplifyOptions::two_sided) and the parts' runs drop: as in
  // simplify_partitioned, such an input is not simplified by parts.
  if (duplicates && options.two_sided != TwoSided::None) return false;

  // Weld: a cut vertex never moved and was never removed (it was locked), so the parts' copies
  // of one input vertex are one vertex.
  Mesh merged;
  std::unordered_map<std::uint32_t, std::uint32_t> welded;  // cut input vertex -> merged vertex
  welded.reserve(std::size_t(cut_vertices));
  std::size_t contractions = 0;
  double max_error = 0;
  std::vector<std::uint64_t> part_end;  // per part: the end of its faces in `merged`
  for (PartOutput& out : outputs) {
    std::vector<std::uint32_t> to_merged(out.mesh.vertex_count());
    for (std::size_t u = 0; u < to_merged.size(); ++u) {
      if (out.cut[u]) {
        const auto [it, fresh] =
            welded.try_emplace(out.input_vertex[u], std::uint32_t(merged.vertex_count()));
        to_merged[u] = it->second;
        if (!fresh) continue;
      } else {
        to_merged[u] = std::uint32_t(merged.vertex_count());
      }
      merged.positions.insert(merged.positions.end(), &out.mesh.positions[3 * u],
                              &out.mesh.positions[3 * u] + 3);
    }
    for (std::uint32_t v : out.mesh.indices) merged.indices.push_back(to_merged[v]);
    part_end.push_back(merged.face_count());
    contractions += out.contractions;
    max_error = std::max(max_error, out.max_error);
    out = PartOutput{};
  }
  std::vector<PartOutput>().swap(outputs);
  if (report) *report = {parts, cut_vertices, merged.face_count()};
  core::release_free_memory();

  // The final pass over the welded parts, the cuts no longer locked, to the whole target.
  const SimplifyOptions last = partition_detail::final_pass_options(options, total);
  struct Forward : SimplifyObserver {
    const std::function<void(double)>* progress;
    bool on_progress(double f) override {
      (*progress)(0.75 + 0.15 * f);
      return true;
    }
  } observer;
  observer.progress = &progress;
  SimplifyResult& r = result;
  r = simplify(std::move(merged), last, &observer);
  r.input_faces = all_faces;
  r.contractions += contractions;
  r.max_error = std::max(r.max_error, max_error);
  if (options.refit_rounds > 0 && r.contractions > 0) {
    refit_by_parts(r.mesh, r.face_source, part_end, options, plan.concurrent, read_part);
    progress(1.0);
  }
  // The provenance is of the welded parts, and the refit's repair changed faces: none is given.
  r.vertex_source.clear(), r.face_source.clear(), r.output_vertex_of_input.clear();
  return true;
}

}  // namespace qem::outofcore
