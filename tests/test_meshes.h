// Small meshes built in code for the unit tests (no files needed).
#pragma once

#include <cstddef>
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <utility>

#include "qem/mesh.h"

namespace qem::test {

/// Flat n x n grid of quads (2 n^2 triangles) in the z = 0 plane, spanning [0,1]^2. Open boundary.
Mesh grid(int n);
/// Height field z = f(x, y) on an n x n grid over [0,1]^2.
Mesh height_field(int n, double (*f)(double, double));
/// Icosphere of unit radius, `level` subdivisions (20 * 4^level faces). Closed, manifold, genus 0.
Mesh icosphere(int level);
/// Axis-aligned unit cube [0,1]^3, 12 triangles, outward orientation.
Mesh cube();
/// Regular tetrahedron, 4 faces.
Mesh tetrahedron();
/// Applies p -> p * scale + offset to every vertex.
Mesh transformed(Mesh mesh, double scale, double ox, double oy, double oz);
/// Concatenates two meshes (indices of `b` shifted).
Mesh concatenated(const Mesh& a, const Mesh& b);
// With appearance attributes (seams, charts):
/// A latitude-longitude sphere (TEXCOORD_0, NORMAL) with a little relief, whose column u = 1
/// repeats the positions of u = 0 with other UVs (a UV seam, split vertices as exporters write
/// them), and whose poles are one position with a wedge per segment.
Mesh uv_sphere(int rings, int segments);
/// A cube of side 2 whose six sides are n x n grids, each its own UV chart (a cell of a 3 x 2
/// atlas) with its own vertices, so that every cube edge is a UV seam. `relief` bulges each side
/// (zero on the cube's edges, so the sides still meet); normals are the side's (flat shading) or
/// the position's direction. With `block` > 0, each side is cut further into block x block-cell
/// charts (many small UV islands), and the sides of +x, +y, +z have material 0, the others 1.
Mesh uv_cube(int n, double relief, bool flat_normals, int block = 0);
/// A wavy n x n grid over the unit square (TEXCOORD_0) whose cell (i, j) lies in UV chart
/// chart(i, j) (two numbers): every chart has its own vertices and UVs (shifted in the atlas by its
/// numbers, so neighbouring charts' UVs differ), so chart boundaries are seams and the points where
/// k charts meet hold k wedges.
Mesh chart_grid(int n, const std::function<std::pair<int, int>(int, int)>& chart);
/// The same cut into `block` x `block` cell charts.
Mesh chart_grid(int n, int block);
/// Edges used by one face once the vertices are welded by position: on a closed mesh, the holes
/// and the cracks a simplification opened along a seam. With `square`, those on the unit square's
/// outline (a flat grid's own border) are not counted.
std::size_t open_edges_welded(const Mesh& m, bool square = false);
/// m's first attribute of this kind (a test failure if it has none).
const VertexAttribute& attribute(const Mesh& m, AttributeKind kind);

// glTF documents built in code:
/// RFC 4648 base64 of `bytes` (a data: URI's payload).
std::string base64(const std::string& bytes);
/// The text of glTF document `doc` with `bin` as its only buffer, embedded as a data: URI.
std::string gltf_text(nlohmann::json doc, const std::string& bin);
/// The qem::Error message of reading glTF `bytes` named `name`, "" when they read.
std::string gltf_error(const std::string& bytes, const std::string& name);
/// `m`'s triangles (positions, and its texture coordinates and normals when it has them; Draco ids
/// in that order) as a Draco bitstream (libdraco's encoder); positions quantized to `position_bits`
/// bits in the mesh's own box, or stored as they are (0).
std::string draco_bitstream(const Mesh& m, int position_bits = 0);
/// `m` (positions, TEXCOORD_0, NORMAL) as one Draco-compressed primitive (libdraco's encoder, no
/// quantization: the values come back exactly): the bitstream (`bin`, to embed with gltf_text) is
/// the only buffer view, the accessors have none, as the extension writes them, the indices
/// unsigned shorts. Draco ids: POSITION 0, TEXCOORD_0 1, NORMAL 2.
nlohmann::json draco_document(const Mesh& m, std::string& bin);
/// Removes from a glTF document's JSON what tinygltf writes or leaves out for its default value
/// (the same meaning either way): `mode: 4`, `normalized: false`, the materials' default factors,
/// alpha mode, texture coordinate sets and scales, and an empty material list.
void erase_gltf_defaults(nlohmann::json& j);

/// The path of a file in ../shared/data, or "" when the shared folder is absent.
std::string shared_data(const std::string& name);
/// A fresh empty temporary directory for this test process.
std::string temp_dir();
/// The whole content of a file ("" if it cannot be read).
std::string slurp(const std::string& path);
/// Runs `qem ARGS -q` (the CLI under test) through the shell and gives its exit status.
int run_qem_quietly(const std::string& args);

}  // namespace qem::test
