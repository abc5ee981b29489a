// Shared pieces of the mesh readers: error helpers that name the file and the line or element, a
// text cursor over an in-memory file (fast_float / from_chars, no iostreams), and the polygon sink
// that fan-triangulates and validates faces.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "qem/error.h"
#include "qem/io.h"
#include "qem/mesh.h"

namespace qem::io {

/// "<name>: <what>".
[[noreturn]] void fail(const std::string& name, const std::string& what);
/// "<name>, line <line>: <what>": the text of a located error or warning.
std::string at_line(const std::string& name, std::size_t line, const std::string& what);
/// Throws at_line(...) (text formats).
[[noreturn]] void fail_line(const std::string& name, std::size_t line, const std::string& what);
/// "<name>, <element> <index>: <what>" (binary formats; index is 0-based).
[[noreturn]] void fail_element(const std::string& name, std::string_view element, std::size_t index,
                               const std::string& what);

/// A whole file in memory: mapped read-only (no copy, no zero-filling), or read into a buffer
/// when mapping is not possible. Throws qem::Error naming the file when it cannot be read.
class FileData {
 public:
  explicit FileData(const std::string& path);
  ~FileData();
  FileData(const FileData&) = delete;
  FileData& operator=(const FileData&) = delete;
  std::string_view bytes() const { return {data_, size_}; }

 private:
  const char* data_ = nullptr;
  std::size_t size_ = 0;
  void* map_ = nullptr;
  std::string buffer_;
};

/// True when a*b <= limit, without overflow: the guard used before every reserve() driven by a count
/// read from the file, so a lying header cannot make us allocate memory the data does not back.
inline bool fits(std::uint64_t a, std::uint64_t b, std::uint64_t limit) { return b == 0 || a <= limit / b; }

/// Forward cursor over text with a line counter. `continuation` enables OBJ's backslash-newline
/// joining; `comment` (0 = none) starts a comment running to the end of the line.
class TextCursor {
 public:
  TextCursor(std::string_view text, const std::string& name, char comment, bool continuation,
             std::size_t first_line = 1)
      : p_(text.data()),
        end_(text.data() + text.size()),
        name_(name),
        comment_(comment),
        continuation_(continuation),
        line_(first_line) {}

  std::size_t line() const { return line_; }
  bool at_end() const { return p_ >= end_; }
  const char* pos() const { return p_; }
  [[noreturn]] void fail(const std::string& what) const { fail_line(name_, line_, what); }

  /// Skips spaces, tabs, '\r' (and backslash-newline when enabled) without leaving the line.
  void skip_blank() {
    while (p_ < end_) {
      char c = *p_;
      if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
        ++p_;
      } else if (continuation_ && c == '\\' && continues_line(p_)) {
        while (*p_ != '\n') ++p_;
        ++p_;
        ++line_;
      } else {
        break;
      }
    }
  }
  /// After skip_blank(): at the end of the statement (newline, comment or end of text)?
  bool at_line_end() const { return p_ >= end_ || *p_ == '\n' || (comment_ && *p_ == comment_); }

  /// Skips the rest of the line (with its continuations and comment) and the newline.
  void next_line() {
    while (p_ < end_) {
      const char* nl = static_cast<const char*>(std::memchr(p_, '\n', static_cast<std::size_t>(end_ - p_)));
      if (!nl) {
        p_ = end_;
        return;
      }
      bool joined = continuation_ && ends_with_backslash(nl);
      p_ = nl + 1;
      ++line_;
      if (!joined) return;
    }
  }

  /// Skips whitespace, newlines and comments (token-oriented formats). False at end of text.
  bool skip_space() {
    while (p_ < end_) {
      char c = *p_;
      if (c == '\n') {
        ++line_;
        ++p_;
      } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
        ++p_;
      } else if (comment_ && c == comment_) {
        next_line();
      } else {
        return true;
      }
    }
    return false;
  }

  /// The run of non-blank characters at the cursor (may be empty).
  std::string_view word() {
    const char* b = p_;
    while (p_ < end_ && !is_delim(*p_)) ++p_;
    return {b, static_cast<std::size_t>(p_ - b)};
  }

  /// Parses a floating-point number at the cursor (must be followed by a delimiter).
  bool try_number(double& value);
  /// Single precision, rounded once from the text (ASCII PLY `float` properties, ASCII STL), so
  /// an ASCII file reads back exactly like its binary twin.
  bool try_number(float& value);
  double number(const char* what) {
    double v;
    if (!try_number(v)) fail_expected(what);
    return v;
  }
  /// Parses a signed integer at the cursor; `allow_slash` accepts a following '/' (OBJ v/vt/vn).
  bool try_integer(long long& value, bool allow_slash);
  long long integer(const char* what) {
    long long v;
    if (!try_integer(v, false)) fail_expected(what);
    return v;
  }
  bool starts_with(std::string_view s) const {
    return static_cast<std::size_t>(end_ - p_) >= s.size() && std::string_view(p_, s.size()) == s;
  }
  /// Consumes `c` if it is the next character.
  bool skip_char(char c) {
    if (p_ < end_ && *p_ == c) {
      ++p_;
      return true;
    }
    return false;
  }
  /// The rest of the statement, blanks trimmed at both ends (OBJ `mtllib` / `usemtl` names, which
  /// may contain spaces).
  std::string_view rest_of_line() {
    skip_blank();
    const char* b = p_;
    while (p_ < end_ && *p_ != '\n' && !(comment_ && *p_ == comment_)) ++p_;
    const char* e = p_;
    while (e > b && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r' || e[-1] == '\f' || e[-1] == '\v')) --e;
    return {b, static_cast<std::size_t>(e - b)};
  }
  /// Skips characters up to the next blank/newline (the "/vt/vn" tail of an OBJ index).
  void skip_word() {
    while (p_ < end_ && !is_delim(*p_)) ++p_;
  }

  [[noreturn]] void fail_expected(const char* what) const;

  bool is_delim(char c) const {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v' ||
           (comment_ && c == comment_);
  }

 private:
  template <class T>
  bool parse_real(T& value);
  bool continues_line(const char* bs) const {
    const char* q = bs + 1;
    if (q < end_ && *q == '\r') ++q;
    return q < end_ && *q == '\n';
  }
  bool ends_with_backslash(const char* nl) const {
    const char* q = nl;
    if (q > p_ && q[-1] == '\r') --q;
    return q > p_ && q[-1] == '\\';
  }

  const char* p_;
  const char* end_;
  const std::string& name_;
  char comment_;
  bool continuation_;
  std::size_t line_;
};

/// Collects polygons as fan triangles (first corner shared), counting those with more than 3 corners.
struct PolygonSink {
  std::vector<std::uint32_t>* indices;
  std::size_t polygons = 0;
  void add(const std::uint32_t* corners, std::size_t n) {
    if (n > 3) ++polygons;
    for (std::size_t k = 2; k < n; ++k) {
      indices->push_back(corners[0]);
      indices->push_back(corners[k - 1]);
      indices->push_back(corners[k]);
    }
  }
};

inline bool finite3(double x, double y, double z) {
  return std::isfinite(x) && std::isfinite(y) && std::isfinite(z);
}

/// Readers and writers of each format (one file each). Readers throw qem::Error on malformed input.
Mesh parse_obj(std::string_view bytes, const std::string& name, const LoadOptions& options,
               LoadReport& report);
Mesh parse_ply(std::string_view bytes, const std::string& name, const LoadOptions& options,
               LoadReport& report);
Mesh parse_stl(std::string_view bytes, const std::string& name, const LoadOptions& options,
               LoadReport& report);
Mesh parse_off(std::string_view bytes, const std::string& name, const LoadOptions& options,
               LoadReport& report);
/// True when `bytes` has exactly the size of a binary STL with the triangle count of its header.
bool stl_is_binary(std::string_view bytes);

std::string write_obj(const Mesh& mesh);
std::string write_ply(const Mesh& mesh, bool binary, bool double_precision);
std::string write_stl(const Mesh& mesh, bool binary);
std::string write_off(const Mesh& mesh);

/// Writes `bytes` to a unique temporary file beside `path`, flushes it and renames it over `path`.
void write_file_atomic(const std::string& path, std::string_view bytes);

/// Appends the shortest decimal text that reads back to exactly `v` (std::to_chars).
void append_number(std::string& out, double v);
void append_number(std::string& out, float v);
void append_uint(std::string& out, std::uint64_t v);

/// Throws unless the mesh is well formed for writing (index range, whole triangles, finite
/// coordinates: every reader refuses a non-finite one, so a writer must not produce it).
void check_mesh_for_writing(const Mesh& mesh);

/// Throws unless every coordinate (and, with `with_properties`, every vertex property value) fits
/// in single precision: a float writer would otherwise turn it into infinity, a file no reader
/// takes back. `what` names the output ("STL", "PLY with float values") for the message.
void check_fits_in_float(const Mesh& mesh, bool with_properties, const char* what);

}  // namespace qem::io
