// Reading a binary PLY or binary STL in chunks, never the whole file: the input side of the
// out-of-core simplification (Lindstrom 2000 reads its input as a stream of triangles). Errors
// name the file and the element, like the in-memory readers (src/io).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace qem::outofcore {

class MeshStream {
 public:
  /// Opens `path` and reads its header. Throws qem::Error for a malformed header and for what
  /// cannot be streamed (ASCII PLY or STL, other formats, a vertex element with list properties).
  explicit MeshStream(const std::string& path);
  ~MeshStream();
  MeshStream(const MeshStream&) = delete;
  MeshStream& operator=(const MeshStream&) = delete;

  /// True for a PLY (vertices indexed by faces), false for an STL (a triangle soup).
  bool indexed() const;
  /// PLY: the vertex element's count; STL: 3 per triangle.
  std::uint64_t vertex_count() const;
  /// PLY: the face element's count (polygons count once; they are fan-triangulated when read);
  /// STL: triangles.
  std::uint64_t face_count() const;
  std::uint64_t file_size() const;
  /// Bytes read from the file so far (all passes), for progress reports.
  std::uint64_t bytes_read() const;
  const std::string& path() const;

  /// PLY: what the stream does not read of the vertex and face elements (their other properties:
  /// normals, colours, texture coordinates...), as "element property"; other elements are named
  /// whole. Empty for an STL.
  std::vector<std::string> unread() const;

  /// PLY: every vertex in order, a chunk at a time: `xyz` holds 3 * n coordinates.
  void read_vertices(const std::function<void(const double* xyz, std::size_t n)>& chunk);
  /// PLY: every face fan-triangulated, a chunk at a time: `corners` holds 3 * n vertex indices, all
  /// checked against vertex_count().
  void read_triangles(const std::function<void(const std::uint32_t* corners, std::size_t n)>& chunk);
  /// STL: every triangle, a chunk at a time: `xyz` holds 9 * n coordinates.
  void read_soup(const std::function<void(const double* xyz, std::size_t n)>& chunk);

  /// PLY whose x, y, z are little-endian floats (as qem and most tools write them): where the
  /// vertex rows start in the file, their size and the byte offset of x, y and z in a row, so that
  /// the positions can be mapped from the file itself instead of copied. False otherwise.
  bool float_vertex_layout(std::uint64_t& offset, std::size_t& row, std::size_t at[3]) const;

  /// True when `path` names a format read by MeshStream (by extension: .ply, .stl).
  static bool streamable_extension(const std::string& path);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace qem::outofcore
