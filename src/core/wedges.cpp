#include "core/wedges.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>

#include "core/attribute_weight.h"
#include "qem/error.h"

namespace qem::core {

// A wedge's quadric row: A (6: a00 a01 a02 a11 a12 a22), b (3), c, W, then per interpolated
// component G (3) and D. Q(p, s) = p'Ap + 2 b.p + c + sum_j (W s_j^2 - 2 s_j (G_j.p + D_j)).
namespace {

constexpr std::uint32_t kHead = 11;

// Adds, for every interpolated channel, the face's linear fit g.p + d of the corner values (g in
// the face's plane: the gradient of the barycentric interpolation) to each corner wedge, weighted
// by the face's area (HG99 §2's area weighting, so the error stays a surface integral).
void add_face(Wedges& wg, const Vec3 p[3], const std::uint32_t w[3]) {
  const Vec3 e1 = p[1] - p[0], e2 = p[2] - p[0], n = cross(e1, e2);
  const double n2 = dot(n, n);
  if (!(n2 > 0)) return;
  const double area = std::sqrt(n2) / 2;
  const Vec3 u = cross(e2, n) * (1.0 / n2), v = cross(n, e1) * (1.0 / n2);
  for (int k = 0; k < 3; ++k) {
    double* q = &wg.quadric[std::size_t(w[k]) * wg.quadric_width];
    q[10] += area;
    std::uint32_t j = 0;
    for (const Channel& ch : wg.channels) {
      if (ch.weight == 0) continue;
      for (std::uint32_t c = 0; c < ch.components; ++c, ++j) {
        const auto s = [&](int corner) { return ch.weight * wg.value[std::size_t(w[corner]) * wg.width + ch.first + c]; };
        const Vec3 g = u * (s(1) - s(0)) + v * (s(2) - s(0));
        const double d = s(0) - dot(g, p[0]);
        q[0] += area * g.x * g.x, q[1] += area * g.x * g.y, q[2] += area * g.x * g.z;
        q[3] += area * g.y * g.y, q[4] += area * g.y * g.z, q[5] += area * g.z * g.z;
        q[6] += area * d * g.x, q[7] += area * d * g.y, q[8] += area * d * g.z;
        q[9] += area * d * d;
        double* gd = q + kHead + 4 * j;
        gd[0] += area * g.x, gd[1] += area * g.y, gd[2] += area * g.z, gd[3] += area * d;
      }
    }
  }
}

}  // namespace

namespace {

// Hoppe 1999's quadric of one wedge row q (or of several rows summed: row(i) gives the sum), each
// interpolated component s_j at its optimum (G_j.p + D_j) / W: the head's A, b, c less
// sum_j (G_j, D_j)(G_j, D_j)' / W, a plain quadric in p.
template <class Row>
Quadric reduce(const Row& row, std::uint32_t components) {
  Quadric r;
  r.a00 = row(0), r.a01 = row(1), r.a02 = row(2), r.a11 = row(3), r.a12 = row(4), r.a22 = row(5);
  r.b0 = row(6), r.b1 = row(7), r.b2 = row(8), r.c = row(9);
  r.weight = 0;  // it adds error, not surface
  const double W = row(10);
  if (!(W > 0)) return r;
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0, xd = 0, yd = 0, zd = 0, dd = 0;
  for (std::uint32_t j = 0; j < components; ++j) {
    const std::uint32_t at = kHead + 4 * j;
    const double gx = row(at), gy = row(at + 1), gz = row(at + 2), d = row(at + 3);
    xx += gx * gx, xy += gx * gy, xz += gx * gz, yy += gy * gy, yz += gy * gz, zz += gz * gz;
    xd += gx * d, yd += gy * d, zd += gz * d, dd += d * d;
  }
  const double inv = 1 / W;
  r.a00 -= xx * inv, r.a01 -= xy * inv, r.a02 -= xz * inv, r.a11 -= yy * inv, r.a12 -= yz * inv;
  r.a22 -= zz * inv, r.b0 -= xd * inv, r.b1 -= yd * inv, r.b2 -= zd * inv, r.c -= dd * inv;
  return r;
}

// The quadric row of w with the rows of `merged` added, in `row` (or `big` when wider).
const double* summed_row(const Wedges& wg, std::uint32_t w, const std::uint32_t* merged, std::size_t count,
                         double* row, std::size_t row_size, std::vector<double>& big) {
  double* q = row;
  if (wg.quadric_width > row_size) big.resize(wg.quadric_width), q = big.data();
  const double* a = &wg.quadric[std::size_t(w) * wg.quadric_width];
  for (std::uint32_t i = 0; i < wg.quadric_width; ++i) q[i] = a[i];
  for (std::size_t k = 0; k < count; ++k) {
    const double* b = &wg.quadric[std::size_t(merged[k]) * wg.quadric_width];
    for (std::uint32_t i = 0; i < wg.quadric_width; ++i) q[i] += b[i];
  }
  return q;
}

}  // namespace

Quadric Wedges::reduced(std::uint32_t w, std::uint32_t w2) const {
  return w2 == kNoVertex ? reduced(w, nullptr, 0) : reduced(w, &w2, 1);
}

Quadric Wedges::reduced(std::uint32_t w, const std::uint32_t* merged, std::size_t count) const {
  const std::uint32_t components = (quadric_width - kHead) / 4;
  const double* a = &quadric[std::size_t(w) * quadric_width];
  // One or two rows (every interior collapse, most along a seam): read in place, not summed first.
  if (count == 0) return reduce([a](std::uint32_t i) { return a[i]; }, components);
  if (count == 1) {
    const double* b = &quadric[std::size_t(merged[0]) * quadric_width];
    return reduce([a, b](std::uint32_t i) { return a[i] + b[i]; }, components);
  }
  double row[kHead + 4 * 32];
  std::vector<double> big;
  const double* q = summed_row(*this, w, merged, count, row, sizeof row / sizeof row[0], big);
  return reduce([q](std::uint32_t i) { return q[i]; }, components);
}

double Wedges::error_at(std::uint32_t w, const std::uint32_t* merged, std::size_t count, const Vec3& p) const {
  double row[kHead + 4 * 32];
  std::vector<double> big;
  const double* q = summed_row(*this, w, merged, count, row, sizeof row / sizeof row[0], big);
  // Q(p, s) = p'Ap + 2 b.p + c + sum_j (W s_j^2 - 2 s_j (G_j.p + D_j)), s the weighted values.
  double e = p.x * (q[0] * p.x + 2 * q[1] * p.y + 2 * q[2] * p.z) + p.y * (q[3] * p.y + 2 * q[4] * p.z) +
             q[5] * p.z * p.z + 2 * (q[6] * p.x + q[7] * p.y + q[8] * p.z) + q[9];
  const double W = q[10];
  std::uint32_t j = 0;
  for (const Channel& ch : channels) {
    if (ch.weight == 0) continue;
    for (std::uint32_t c = 0; c < ch.components; ++c, ++j) {
      const double* gd = q + kHead + 4 * j;
      const double s = ch.weight * value[std::size_t(w) * width + ch.first + c];
      e += W * s * s - 2 * s * (gd[0] * p.x + gd[1] * p.y + gd[2] * p.z + gd[3]);
    }
  }
  return std::max(e, 0.0);
}

void Wedges::update_values(std::uint32_t w, const Vec3& p) {
  const double* q = &quadric[std::size_t(w) * quadric_width];
  const double W = q[10];
  if (!(W > 0)) return;
  std::uint32_t j = 0;
  for (const Channel& ch : channels) {
    if (ch.weight == 0) continue;
    for (std::uint32_t c = 0; c < ch.components; ++c, ++j) {
      const double* gd = q + kHead + 4 * j;
      value[std::size_t(w) * width + ch.first + c] = (gd[0] * p.x + gd[1] * p.y + gd[2] * p.z + gd[3]) / W / ch.weight;
    }
  }
}

void Wedges::refit_kept(std::uint32_t w, const Vec3& p) {
  std::uint32_t sides[8], count = 0;
  sides[count++] = w;
  for (std::uint32_t x = next[w]; x != w && count < 8; x = next[x])
    if (source[x] == source[w] && material[x] == material[w]) sides[count++] = x;
  double W = 0;
  for (std::uint32_t i = 0; i < count; ++i) W += quadric[std::size_t(sides[i]) * quadric_width + 10];
  if (!(W > 0)) return;
  std::uint32_t j = 0;
  for (const Channel& ch : channels) {
    if (ch.weight == 0) continue;
    if (ch.kind == AttributeKind::TexCoord) {  // on the chart's edge: kept
      j += ch.components;
      continue;
    }
    for (std::uint32_t c = 0; c < ch.components; ++c, ++j) {
      double g = 0;
      for (std::uint32_t i = 0; i < count; ++i) {
        const double* gd = &quadric[std::size_t(sides[i]) * quadric_width + kHead + 4 * j];
        g += gd[0] * p.x + gd[1] * p.y + gd[2] * p.z + gd[3];
      }
      for (std::uint32_t i = 0; i < count; ++i) value[std::size_t(sides[i]) * width + ch.first + c] = g / W / ch.weight;
    }
  }
}

void Wedges::merge(std::uint32_t survivor, std::uint32_t removed, bool moved, bool crossed, const Vec3& p,
                   const std::vector<std::pair<std::uint32_t, std::uint32_t>>& map, const WorkingMesh& m,
                   const std::vector<std::uint32_t>& faces) {
  for (const auto& [r, s] : map) {
    double* into = &quadric[std::size_t(s) * quadric_width];
    const double* from = &quadric[std::size_t(r) * quadric_width];
    for (std::uint32_t i = 0; i < quadric_width; ++i) into[i] += from[i];
    merged_into[r] = s;
  }
  first[removed] = kNoVertex;
  if (!moved) {
    // The survivor stays, and so do its texture coordinates (a seam's stay exactly on the chart's
    // edge). Its other values take their optimum at its position for the faces it now has: the cost
    // (place_with_wedges) was of that optimum, and a kept normal no longer fits a fan that grew. A
    // crossing (permissive) was costed with the values kept, and keeps them.
    // The two sides of a mirror line (wedges of one input vertex and material, equal values) take
    // one optimum, over both sides' faces: they stay equal, one vertex in the output as in the
    // input (build_wedge_output).
    if (!crossed)
      for (const auto& [r, s] : map) refit_kept(s, p);
    return;
  }
  std::uint32_t w = first[survivor];
  do {
    update_values(w, p);
    // Texture coordinates interpolate, never extrapolate: the optimum of Hoppe's quadric at the
    // new position may lie beyond the chart (past the atlas's edge at a pole or a seam). The new
    // vertex lies among its neighbours, so its UVs stay within the box of their UVs on its faces.
    // (Not the box of the two merged ends' UVs: a vertex placed off the edge, as the optimal
    // placement does on a curved surface, has UVs off the edge's UV segment too.)
    for (const Channel& ch : channels) {
      if (ch.kind != AttributeKind::TexCoord || ch.weight == 0) continue;
      for (std::uint32_t c = 0; c < ch.components; ++c) {
        double low = std::numeric_limits<double>::infinity(), high = -low;
        for (std::uint32_t f : faces) {
          const std::uint32_t* t = m.face(f);
          const std::uint32_t* cw = &m.corner_wedge[3 * std::size_t(f)];
          if (!((t[0] == survivor && cw[0] == w) || (t[1] == survivor && cw[1] == w) ||
                (t[2] == survivor && cw[2] == w)))
            continue;
          for (int k = 0; k < 3; ++k) {
            if (t[k] == survivor) continue;
            const double u = value[std::size_t(cw[k]) * width + ch.first + c];
            low = std::min(low, u), high = std::max(high, u);
          }
        }
        if (low <= high) {
          double& v = value[std::size_t(w) * width + ch.first + c];
          v = std::clamp(v, low, high);
        }
      }
    }
    w = next[w];
  } while (w != first[survivor]);
}

void Wedges::drop_unused(std::vector<std::uint32_t>& emptied) {
  for (std::uint32_t w : emptied) {
    if (corners[w] != 0 || merged_into[w] != kNoVertex || vertex[w] == kNoVertex) continue;
    std::uint32_t& head = first[vertex[w]];
    if (head == kNoVertex || next[w] == w) continue;  // a removed vertex, or its last wedge
    std::uint32_t before = w;
    while (next[before] != w) before = next[before];
    next[before] = next[w];
    next[w] = w;
    if (head == w) head = before;
  }
  emptied.clear();
}

void Wedges::renumber(const std::vector<std::uint32_t>& vertex_to, std::size_t count) {
  for (std::uint32_t& v : vertex) v = v == kNoVertex ? kNoVertex : vertex_to[v];
  squeeze_by(vertex_to, count, first);
  if (!protect.empty()) squeeze_by(vertex_to, count, protect);
}

std::uint32_t Wedges::final_wedge_of_input(std::uint32_t v) const {
  std::uint32_t w = of_input[v];
  if (w == kNoVertex) return w;
  while (merged_into[w] != kNoVertex) w = merged_into[w];
  return w;
}

namespace {

// SeamMode::Creases: every vertex whose wedges' texture coordinates
// differ is protected, so that only creases and colour boundaries are crossed.
void protect_uv_seams(Wedges& wg, std::uint32_t vertices) {
  if (wg.protect.empty()) wg.protect.assign(vertices, 0);
  for (std::uint32_t v = 0; v < vertices; ++v) {
    const std::uint32_t a = wg.first[v];
    if (a == kNoVertex || wg.protect[v]) continue;
    for (std::uint32_t b = wg.next[a]; b != a && !wg.protect[v]; b = wg.next[b])
      for (const Channel& ch : wg.channels)
        if (ch.kind == AttributeKind::TexCoord)
          for (std::uint32_t c = 0; c < ch.components; ++c)
            if (wg.value[std::size_t(a) * wg.width + ch.first + c] !=
                wg.value[std::size_t(b) * wg.width + ch.first + c])
              wg.protect[v] = 1;
  }
}

}  // namespace

Wedges build_wedges(MeshView in, const std::vector<std::uint32_t>& internal, WorkingMesh& m,
                    const SimplifyOptions& options) {
  Wedges wg;
  std::uint32_t interpolated = 0;
  for (const VertexAttribute& a : in.attributes) {
    const double weight = attribute_weight(a.kind, options.attribute_weights);
    wg.channels.push_back({a.kind, wg.width, a.components, weight});
    wg.width += a.components;
    if (weight > 0) interpolated += a.components;
  }
  wg.quadric_width = kHead + 4 * interpolated;

  // The first texture coordinates, whose triangles' orientation tells the two sides of a mirror
  // line apart.
  const VertexAttribute* uv = nullptr;
  for (const VertexAttribute& a : in.attributes)
    if (!uv && a.kind == AttributeKind::TexCoord && a.components >= 2) uv = &a;
  const auto mirrored = [&](std::uint32_t source) {
    if (!uv) return false;
    const auto at = [&](int k, int c) { return uv->values[std::size_t(in.indices[3 * std::size_t(source) + k]) * uv->components + c]; };
    const double du1 = at(1, 0) - at(0, 0), dv1 = at(1, 1) - at(0, 1), du2 = at(2, 0) - at(0, 0), dv2 = at(2, 1) - at(0, 1);
    return du1 * dv2 - dv1 * du2 < 0;
  };

  // One wedge per input vertex, material and side of a mirror line (faces whose UV triangles turn
  // the other way: a mirrored atlas's mirror line is a seam although both sides share the UV
  // indices), in the order of first use by a working face. Keyed by `material * 2 + side`.
  std::vector<std::uint32_t> wedge_of(in.vertex_count(), kNoVertex);
  std::unordered_map<std::uint64_t, std::uint32_t> other_material;  // (vertex, material) beyond the first
  std::vector<std::uint32_t> material_of;
  auto wedge = [&](std::uint32_t v, std::uint32_t material) {
    std::uint32_t& w = wedge_of[v];
    if (w != kNoVertex && material_of[w] == material) return w;
    if (w != kNoVertex) {
      auto [it, fresh] = other_material.try_emplace((std::uint64_t(v) << 32) | material, std::uint32_t(wg.count()));
      if (!fresh) return it->second;
    } else {
      w = std::uint32_t(wg.count());
    }
    const std::uint32_t id = std::uint32_t(wg.count());
    wg.vertex.push_back(internal[v]);
    wg.source.push_back(v);
    wg.material.push_back(material / 2);
    material_of.push_back(material);
    for (const VertexAttribute& a : in.attributes)
      for (std::uint32_t c = 0; c < a.components; ++c)
        wg.value.push_back(a.values[std::size_t(v) * a.components + c]);
    return id;
  };
  m.corner_wedge.resize(m.tri.size());
  for (std::size_t f = 0; f < m.face_source.size(); ++f) {
    const std::uint32_t source = m.face_source[f];
    const std::uint32_t material =
        2 * (in.face_materials.empty() ? 0 : in.face_materials[source]) + (mirrored(source) ? 1 : 0);
    for (int k = 0; k < 3; ++k) m.corner_wedge[3 * f + k] = wedge(in.indices[3 * std::size_t(source) + k], material);
  }
  wg.of_input = std::move(wedge_of);

  // The rings of wedges per working vertex.
  wg.first.assign(m.vertex_count(), kNoVertex);
  wg.next.resize(wg.count());
  wg.merged_into.assign(wg.count(), kNoVertex);
  for (std::uint32_t w = 0; w < wg.count(); ++w) {
    std::uint32_t& head = wg.first[wg.vertex[w]];
    if (head == kNoVertex) {
      head = w, wg.next[w] = w;
    } else {
      wg.next[w] = wg.next[head], wg.next[head] = w;
    }
  }
  wg.permissive = options.seams == SeamMode::Creases || options.seams == SeamMode::Permissive;
  wg.junctions = options.seams == SeamMode::Junctions;
  if (!options.vertex_protect.empty()) {
    if (options.vertex_protect.size() != in.vertex_count())
      throw Error("vertex_protect has " + std::to_string(options.vertex_protect.size()) + " entries for " +
                  std::to_string(in.vertex_count()) + " vertices");
    wg.protect.assign(m.vertex_count(), 0);
    for (std::uint32_t w = 0; w < wg.count(); ++w)
      if (options.vertex_protect[wg.source[w]]) wg.protect[wg.vertex[w]] = 1;
  }
  if (options.seams == SeamMode::Creases) protect_uv_seams(wg, m.vertex_count());
  wg.corners.assign(wg.count(), 0);
  for (std::uint32_t w : m.corner_wedge) ++wg.corners[w];
  wg.renew_quadrics(m);
  return wg;
}

void Wedges::renew_quadrics(const WorkingMesh& m) {
  quadric.assign(count() * std::size_t(quadric_width), 0);
  for (std::uint32_t f = 0; f < m.face_alive.size(); ++f) {
    if (!m.face_alive[f]) continue;
    const std::uint32_t* t = m.face(f);
    const Vec3 p[3] = {m.pos[t[0]], m.pos[t[1]], m.pos[t[2]]};
    add_face(*this, p, &m.corner_wedge[3 * std::size_t(f)]);
  }
}

namespace {

// The squared weighted distance between the values of wedges x and y (interpolated channels).
double value_distance(const Wedges& wg, std::uint32_t x, std::uint32_t y) {
  double d2 = 0;
  for (const Channel& ch : wg.channels)
    for (std::uint32_t c = 0; c < ch.components; ++c) {
      const double d = ch.weight * (wg.value[std::size_t(x) * wg.width + ch.first + c] -
                                    wg.value[std::size_t(y) * wg.width + ch.first + c]);
      d2 += d * d;
    }
  return d2;
}

// The faces of one edge map_wedges tells apart; more (a fan of sheets) leaves the strict rules.
constexpr std::size_t kMaxEdgeFaces = 8;

// The survivor's and the removed vertex's wedges at their corners of face f (a face of the edge).
std::pair<std::uint32_t, std::uint32_t> edge_face_wedges(const WorkingMesh& m, std::uint32_t f, std::uint32_t survivor,
                                                         std::uint32_t removed) {
  const std::uint32_t* t = m.face(f);
  std::uint32_t ws = kNoVertex, wr = kNoVertex;
  for (int k = 0; k < 3; ++k) {
    if (t[k] == survivor) ws = m.corner_wedge[3 * std::size_t(f) + k];
    if (t[k] == removed) wr = m.corner_wedge[3 * std::size_t(f) + k];
  }
  return {ws, wr};
}

// The permissive map: the strict rules failed, so the collapse crosses a seam. A removed wedge on
// an edge face goes to the survivor's wedge on that face (the first one met), any other to the
// survivor's wedge of its material with the nearest values; none of its material: refused.
bool map_crossing(const WorkingMesh& m, const Wedges& wg, std::uint32_t survivor, std::uint32_t removed,
                  std::vector<std::pair<std::uint32_t, std::uint32_t>>& map) {
  map.clear();
  for (std::uint32_t f : m.vertex_faces[survivor]) {
    if (!m.face_alive[f] || !m.face_has(f, removed)) continue;
    const auto [ws, wr] = edge_face_wedges(m, f, survivor, removed);
    bool known = false;
    for (const auto& [r, s] : map) known |= r == wr;
    if (!known) map.push_back({wr, ws});
  }
  std::uint32_t w = wg.first[removed];
  do {
    bool known = false;
    for (const auto& [r, s] : map) known |= r == w;
    if (!known) {
      std::uint32_t best = kNoVertex;
      double best_d2 = 0;
      std::uint32_t x = wg.first[survivor];
      do {
        if (wg.material[x] == wg.material[w]) {
          const double d2 = value_distance(wg, w, x);
          if (best == kNoVertex || d2 < best_d2) best = x, best_d2 = d2;
        }
        x = wg.next[x];
      } while (x != wg.first[survivor]);
      if (best == kNoVertex) return false;
      map.push_back({w, best});
    }
    w = wg.next[w];
  } while (w != wg.first[removed]);
  return true;
}

}  // namespace

bool map_wedges(const WorkingMesh& m, const Wedges& wg, std::uint32_t survivor, std::uint32_t removed,
                std::vector<std::pair<std::uint32_t, std::uint32_t>>& map, bool* crossed) {
  if (crossed) *crossed = false;
  map.clear();
  // The (survivor, removed) wedges of each face of the edge: these faces die with the collapse.
  std::pair<std::uint32_t, std::uint32_t> edge[kMaxEdgeFaces];
  std::size_t edge_faces = 0;
  bool strict = true;
  for (std::uint32_t f : m.vertex_faces[survivor]) {
    if (!m.face_alive[f] || !m.face_has(f, removed)) continue;
    if (edge_faces == kMaxEdgeFaces) {  // a fan of sheets on one edge: no side is clear
      strict = false;
      break;
    }
    edge[edge_faces++] = edge_face_wedges(m, f, survivor, removed);
  }
  if (edge_faces == 0) return false;  // not an edge: nothing tells the sides apart
  // A wedge all of whose corners are on the edge's faces is vacated by the collapse: unless a
  // removed wedge comes to it, it dies with those faces (drop_unused), and so does the seam it
  // bounds (a crease that ends one face away, a flipped UV triangle).
  const auto vacated = [&](std::uint32_t w, bool at_survivor) {
    std::uint32_t on_edge = 0;
    for (std::size_t i = 0; i < edge_faces; ++i) on_edge += (at_survivor ? edge[i].first : edge[i].second) == w;
    return wg.corners[w] == on_edge;
  };
  std::uint32_t w = wg.first[removed];
  if (strict) do {
    // The survivor's wedges that w meets on the edge's faces: w's faces go on with the one it
    // meets that lives on; meeting two that live on, it would be split (the seam would leave its
    // edges). A vacated w needs no partner; it hands its quadric to the first it meets.
    std::uint32_t to = kNoVertex, living = 0;
    for (std::size_t i = 0; i < edge_faces; ++i) {
      const std::uint32_t ws = edge[i].first;
      if (edge[i].second != w || ws == to) continue;
      if (to == kNoVertex) {
        to = ws, living = !vacated(ws, true);
      } else if (!vacated(ws, true)) {
        if (living) strict = false;
        to = ws, living = 1;
      }
    }
    if (to == kNoVertex) {
      if (!vacated(w, false)) strict = false;  // on no face of the edge: the collapse would move its seam
    } else {
      map.push_back({w, to});
    }
    w = wg.next[w];
  } while (strict && w != wg.first[removed]);
  // Two of the removed end's wedges into one of the survivor's: the seam between them ends at the
  // survivor (a half seam) and shortens along itself, both sides together. Only on a manifold
  // edge: with more faces, the sides are not told apart.
  for (std::size_t i = 0; strict && edge_faces != 2 && i < map.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (map[i].second == map[j].second && !vacated(map[i].first, false) && !vacated(map[j].first, false))
        strict = false;
  if (strict) return true;
  const bool protect = !wg.protect.empty() && (wg.protect[survivor] || wg.protect[removed]);
  const bool may_cross = wg.permissive || (wg.junctions && wg.junction(removed) && wg.junction(survivor));
  if (!may_cross || protect || !map_crossing(m, wg, survivor, removed, map)) return false;
  if (crossed) *crossed = true;
  return true;
}

void lock_seam_vertices(const Wedges& wg, WorkingMesh& m) {
  if (m.locked.empty()) m.locked.assign(m.vertex_count(), 0);
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v)
    if (wg.first[v] != kNoVertex && !wg.single(v)) m.locked[v] = 1;
}

Mesh build_wedge_output(const WorkingMesh& m, const Wedges& wg, MeshView input, std::vector<std::uint32_t>& vertex_source,
                        std::vector<std::uint32_t>& face_source, std::vector<std::uint32_t>* output_vertex_of_input,
                        WedgeRefitData* refit) {
  std::vector<std::uint32_t> faces;
  std::vector<std::uint8_t> used(wg.count(), 0);
  for (std::uint32_t f = 0; f < m.face_alive.size(); ++f)
    if (m.face_alive[f]) {
      faces.push_back(f);
      for (int k = 0; k < 3; ++k) used[m.corner_wedge[3 * std::size_t(f) + k]] = 1;
    }
  std::sort(faces.begin(), faces.end(), [&](std::uint32_t x, std::uint32_t y) { return m.face_source[x] < m.face_source[y]; });
  std::vector<std::uint32_t> survivors;
  for (std::uint32_t w = 0; w < wg.count(); ++w)
    if (used[w]) survivors.push_back(w);
  std::sort(survivors.begin(), survivors.end(), [&](std::uint32_t x, std::uint32_t y) {
    return wg.source[x] != wg.source[y] ? wg.source[x] < wg.source[y] : x < y;
  });
  Mesh out;
  for (const VertexAttribute& a : input.attributes) {
    out.attributes.push_back({a.name, a.kind, a.components, {}});
    out.attributes.back().values.reserve(survivors.size() * a.components);
  }
  // Wedges in use per working vertex: a wedge whose faces all died is no seam any more.
  std::vector<std::uint32_t> used_at(refit ? m.vertex_count() : 0, 0);
  if (refit)
    for (std::uint32_t w : survivors) ++used_at[wg.vertex[w]];
  std::vector<std::uint32_t> remap(wg.count(), kNoVertex);
  std::vector<double> values(wg.width);
  for (std::size_t i = 0; i < survivors.size(); ++i) {
    const std::uint32_t w = survivors[i];
    // The two sides of a mirror line are wedges of one input vertex and material: with equal
    // values (they stayed on the seam) they are one output vertex again, as in the input.
    std::uint32_t same = kNoVertex;
    for (std::size_t j = i; j > 0 && wg.source[survivors[j - 1]] == wg.source[w] && same == kNoVertex; --j) {
      const std::uint32_t x = survivors[j - 1];
      if (wg.material[x] == wg.material[w] && wg.vertex[x] == wg.vertex[w] &&
          std::equal(&wg.value[std::size_t(x) * wg.width], &wg.value[std::size_t(x + 1) * wg.width],
                     &wg.value[std::size_t(w) * wg.width]))
        same = x;
    }
    if (same != kNoVertex) {
      remap[w] = remap[same];
      continue;
    }
    remap[w] = std::uint32_t(vertex_source.size());
    vertex_source.push_back(wg.source[w]);
    const Vec3 p = m.output_position(wg.vertex[w], input);
    out.positions.insert(out.positions.end(), {p.x, p.y, p.z});
    if (refit) refit->on_seam.push_back(used_at[wg.vertex[w]] > 1);
    output_values(wg, w, values.data());
    for (std::size_t i = 0; i < wg.channels.size(); ++i)
      out.attributes[i].values.insert(out.attributes[i].values.end(), values.begin() + wg.channels[i].first,
                                      values.begin() + wg.channels[i].first + wg.channels[i].components);
  }
  for (std::uint32_t f : faces) {
    for (int k = 0; k < 3; ++k) out.indices.push_back(remap[m.corner_wedge[3 * std::size_t(f) + k]]);
    face_source.push_back(m.face_source[f]);
    if (!input.face_materials.empty()) out.face_materials.push_back(input.face_materials[m.face_source[f]]);
  }
  if (output_vertex_of_input) {
    output_vertex_of_input->assign(input.vertex_count(), kNoVertex);
    for (std::uint32_t v = 0; v < input.vertex_count(); ++v) {
      const std::uint32_t w = wg.final_wedge_of_input(v);
      if (w != kNoVertex) (*output_vertex_of_input)[v] = remap[w];
    }
  }
  return out;
}

void output_values(const Wedges& wg, std::uint32_t w, double* out) {
  const double* v = &wg.value[std::size_t(w) * wg.width];
  for (const Channel& ch : wg.channels) {
    double* o = out + ch.first;
    for (std::uint32_t c = 0; c < ch.components; ++c) o[c] = v[ch.first + c];
    if (ch.kind == AttributeKind::Normal && ch.components == 3) {
      const double len = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
      if (len > 0)
        for (int c = 0; c < 3; ++c) o[c] /= len;
    } else if (ch.kind == AttributeKind::Color) {
      for (std::uint32_t c = 0; c < ch.components; ++c) o[c] = std::clamp(o[c], 0.0, 1.0);
    } else if (ch.kind == AttributeKind::JointWeights) {
      double sum = 0;
      for (std::uint32_t c = 0; c < ch.components; ++c) sum += o[c] = std::max(o[c], 0.0);
      if (sum > 0)
        for (std::uint32_t c = 0; c < ch.components; ++c) o[c] /= sum;
    }
  }
}

}  // namespace qem::core
