// The synthetic meshes of `qem generate`: a bumpy icosphere and a torus, built in memory (a Mesh)
// or streamed to a binary PLY in bounded memory, so that anyone can make a billion-triangle test
// mesh. Both ways give the same file for the same size (tests/out_of_core_test.cpp checks it).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "qem/mesh.h"

namespace qem::outofcore {

struct GeneratedCounts {
  std::uint64_t vertices = 0, faces = 0;
};

/// Icosphere subdivided until it has at least `faces` faces (20 * 4^level), radially displaced by
/// a few waves so that it has features worth keeping.
Mesh bumpy_sphere(std::size_t faces);
/// Torus with major radius 1 and minor radius 0.35 on an n x (n/2) grid, n the smallest even
/// number >= 8 with n * (n/2) * 2 >= faces.
Mesh torus(std::size_t faces);

GeneratedCounts bumpy_sphere_counts(std::uint64_t faces);
GeneratedCounts torus_counts(std::uint64_t faces);

/// The largest --faces the streamed generators accept: vertex indices must fit the PLY's int32.
constexpr std::uint64_t kMaxStreamedSphereFaces = 20ull << 26;  // 20 * 4^13, 671 million vertices
constexpr std::uint64_t kMaxStreamedTorusFaces = 2000000000ull;

/// Writes the same mesh as save_mesh(path, bumpy_sphere(faces)) would as binary PLY, but vertex
/// by vertex and face by face, holding only the edges still waiting for their second face (a few
/// per subdivided row) instead of the mesh. Written atomically.
GeneratedCounts write_bumpy_sphere_ply(const std::string& path, std::uint64_t faces);
/// Same for torus(faces), one ring of the grid at a time.
GeneratedCounts write_torus_ply(const std::string& path, std::uint64_t faces);

}  // namespace qem::outofcore
