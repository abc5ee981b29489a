// `qem generate KIND OUTPUT`: synthetic meshes of any size, so that the README's first command
// (and a benchmark) needs no downloaded model. A .ply is streamed to disk (bounded memory, up to
// a billion faces and more); other formats, and meshes with --attributes, are built in memory.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "command.h"
#include "outofcore/mesh_generator.h"
#include "qem/error.h"
#include "qem/io.h"

namespace qem::cli {
namespace {

// Adds smooth normals (area-weighted face normals per position) and a latitude/longitude UV map
// to a closed mesh centred at the origin, splitting vertices where the map is discontinuous: along
// the seam where longitude wraps from 1 to 0 (each face that straddles it gets copies with u + 1),
// and at a pole, where longitude is undefined (one copy per face, u from the face's other corners).
// The result is what a textured asset looks like to the simplifier: wedges at a UV seam, one UV set.
Mesh with_uv_and_normals(const Mesh& in) {
  const std::size_t n = in.vertex_count();
  std::vector<double> normal(3 * n, 0.0), u(n), v(n);
  std::vector<bool> pole(n);
  for (std::size_t f = 0; f < in.indices.size(); f += 3) {
    const double* p[3];
    for (int k = 0; k < 3; ++k) p[k] = &in.positions[3 * std::size_t(in.indices[f + k])];
    const double e1[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const double e2[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    const double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) normal[3 * std::size_t(in.indices[f + k]) + j] += c[j];  // |c| = 2 x area
  }
  for (std::size_t i = 0; i < n; ++i) {
    double* nv = &normal[3 * i];
    const double len = std::sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
    if (len > 0) nv[0] /= len, nv[1] /= len, nv[2] /= len;
    const double* p = &in.positions[3 * i];
    const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]), rxz = std::hypot(p[0], p[2]);
    pole[i] = !(rxz > 1e-12 * r);
    u[i] = pole[i] ? 0 : std::atan2(p[2], p[0]) / (2 * M_PI) + 0.5;
    v[i] = r > 0 ? std::acos(std::clamp(p[1] / r, -1.0, 1.0)) / M_PI : 0;
  }
  Mesh m;
  VertexAttribute uv{"TEXCOORD_0", AttributeKind::TexCoord, 2, {}}, nrm{"NORMAL", AttributeKind::Normal, 3, {}};
  std::map<std::pair<std::uint32_t, std::uint64_t>, std::uint32_t> copy;  // (vertex, variant) -> output
  auto emit = [&](std::uint32_t i, std::uint64_t variant, double cu) {
    auto [it, fresh] = copy.try_emplace({i, variant}, std::uint32_t(m.vertex_count()));
    if (fresh) {
      m.positions.insert(m.positions.end(), {in.positions[3 * i], in.positions[3 * i + 1], in.positions[3 * i + 2]});
      uv.values.insert(uv.values.end(), {cu, v[i]});
      nrm.values.insert(nrm.values.end(), {normal[3 * i], normal[3 * i + 1], normal[3 * i + 2]});
    }
    return it->second;
  };
  for (std::size_t f = 0; f < in.indices.size(); f += 3) {
    const std::uint32_t* t = &in.indices[f];
    double lo = 1, hi = 0;
    for (int k = 0; k < 3; ++k)
      if (!pole[t[k]]) lo = std::min(lo, u[t[k]]), hi = std::max(hi, u[t[k]]);
    const bool wraps = hi - lo > 0.5;
    double cu[3], sum = 0;
    int count = 0;
    for (int k = 0; k < 3; ++k)
      if (!pole[t[k]]) cu[k] = u[t[k]] + (wraps && u[t[k]] < 0.5 ? 1 : 0), sum += cu[k], ++count;
    for (int k = 0; k < 3; ++k) {
      if (pole[t[k]]) m.indices.push_back(emit(t[k], 2 + f / 3, count ? sum / count : 0));
      else m.indices.push_back(emit(t[k], cu[k] >= 1 ? 1 : 0, cu[k]));
    }
  }
  m.attributes = {std::move(uv), std::move(nrm)};
  return m;
}

struct GenerateArgs {
  std::string kind = "sphere", output;
  std::size_t faces = 100000;
  bool attributes = false;
};

const bool registered = register_command(5, [](CLI::App& app) {
  auto args = std::make_shared<GenerateArgs>();
  CLI::App* sub = app.add_subcommand("generate", "Write a synthetic test mesh (bumpy sphere or torus)");
  sub->add_option("kind", args->kind, "sphere (closed, bumpy icosphere) or torus")
      ->required()
      ->check(CLI::IsMember({"sphere", "torus"}));
  sub->add_option("output", args->output, "Output mesh (.obj .ply .stl .off; .obj, .ply or .glb for --attributes)")->required();
  sub->add_option("--faces", args->faces,
                  "At least this many faces (sphere: next 20 * 4^level). A .ply without --attributes is streamed "
                  "to disk in bounded memory (up to 1342177280 sphere or 2000000000 torus faces); other "
                  "outputs are built in memory (up to 200000000)")
      ->capture_default_str();
  sub->add_flag("--attributes", args->attributes,
                "Add smooth normals and a latitude/longitude UV map (TEXCOORD_0) with its seam: the positions "
                "where the map is discontinuous are split into several vertices, as in a textured asset");
  return [args] {
    const bool sphere = args->kind == "sphere";
    if (format_from_extension(args->output) == FileFormat::Ply && !args->attributes) {
      const outofcore::GeneratedCounts n = sphere
                                               ? outofcore::write_bumpy_sphere_ply(args->output, args->faces)
                                               : outofcore::write_torus_ply(args->output, args->faces);
      std::fprintf(stderr, "qem: wrote %s: %llu vertices, %llu faces\n", args->output.c_str(),
                   static_cast<unsigned long long>(n.vertices), static_cast<unsigned long long>(n.faces));
      return 0;
    }
    if (args->faces > 200000000)
      throw Error(
          "--faces is too large for a mesh built in memory (at most 200000000); write a .ply without "
          "--attributes, which is streamed");
    Mesh m = sphere ? outofcore::bumpy_sphere(args->faces) : outofcore::torus(args->faces);
    if (args->attributes) m = with_uv_and_normals(m);
    save_mesh(args->output, m);
    std::fprintf(stderr, "qem: wrote %s: %zu vertices, %zu faces\n", args->output.c_str(), m.vertex_count(),
                 m.face_count());
    return 0;
  };
});

}  // namespace
}  // namespace qem::cli
