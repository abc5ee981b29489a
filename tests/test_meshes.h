// Small meshes built in code for the unit tests (no files needed).
#pragma once

#include <string>

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
/// The path of a file in ../shared/data, or "" when the shared folder is absent.
std::string shared_data(const std::string& name);
/// A fresh empty temporary directory for this test process.
std::string temp_dir();
/// The whole content of a file ("" if it cannot be read).
std::string slurp(const std::string& path);
/// Runs `qem ARGS -q` (the CLI under test) through the shell and gives its exit status.
int run_qem_quietly(const std::string& args);

}  // namespace qem::test
