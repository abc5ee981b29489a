// Error helpers, whole-file reading, number parsing and formatting shared by every format.
#include "io/io_common.h"

#include <fast_float/fast_float.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include "check_mesh.h"

namespace qem::io {

void fail(const std::string& name, const std::string& what) { throw Error(name + ": " + what); }

std::string at_line(const std::string& name, std::size_t line, const std::string& what) {
  return name + ", line " + std::to_string(line) + ": " + what;
}

void fail_line(const std::string& name, std::size_t line, const std::string& what) {
  throw Error(at_line(name, line, what));
}

void fail_element(const std::string& name, std::string_view element, std::size_t index,
                  const std::string& what) {
  throw Error(name + ", " + std::string(element) + " " + std::to_string(index) + ": " + what);
}

FileData::FileData(const std::string& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw Error(path + ": cannot open for reading: " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    int err = errno;
    ::close(fd);
    throw Error(path + ": cannot read: " + std::strerror(err));
  }
  if (S_ISDIR(st.st_mode)) {
    ::close(fd);
    throw Error(path + ": cannot read: is a directory");
  }
  if (!S_ISREG(st.st_mode) && !S_ISFIFO(st.st_mode)) {
    // Devices such as /dev/zero never end: reading them would hang.
    ::close(fd);
    throw Error(path + ": cannot read: not a regular file");
  }
  if (S_ISREG(st.st_mode) && st.st_size > 0) {
    // Private read-only mapping: the pages come straight from the page cache (MAP_POPULATE maps
    // them up front), which costs far less than copying into fresh, zero-filled memory.
    void* m =
        ::mmap(nullptr, static_cast<std::size_t>(st.st_size), PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
    if (m != MAP_FAILED) {
      map_ = m;
      data_ = static_cast<const char*>(m);
      size_ = static_cast<std::size_t>(st.st_size);
      ::close(fd);
      return;
    }
  }
  // Pipes, special files, or mapping refused: read until end of file.
  char chunk[1 << 16];
  for (;;) {
    ssize_t n = ::read(fd, chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      int err = errno;
      ::close(fd);
      throw Error(path + ": read failed: " + std::strerror(err));
    }
    if (n == 0) break;
    buffer_.append(chunk, static_cast<std::size_t>(n));
  }
  ::close(fd);
  data_ = buffer_.data();
  size_ = buffer_.size();
}

FileData::~FileData() {
  if (map_) ::munmap(map_, size_);
}

template <class T>
bool TextCursor::parse_real(T& value) {
  const char* b = p_;
  if (b < end_ && *b == '+') ++b;  // fast_float 3.x rejects a leading '+', which some writers emit
  auto r = fast_float::from_chars(b, end_, value);
  if (r.ec != std::errc() || (r.ptr < end_ && !is_delim(*r.ptr))) return false;
  p_ = r.ptr;
  return true;
}

bool TextCursor::try_number(double& value) { return parse_real(value); }
bool TextCursor::try_number(float& value) { return parse_real(value); }

bool TextCursor::try_integer(long long& value, bool allow_slash) {
  const char* b = p_;
  if (b < end_ && *b == '+') ++b;
  auto r = std::from_chars(b, end_, value);
  if (r.ec != std::errc()) return false;
  if (r.ptr < end_ && !is_delim(*r.ptr) && !(allow_slash && *r.ptr == '/')) return false;
  p_ = r.ptr;
  return true;
}

void TextCursor::fail_expected(const char* what) const {
  std::string got;
  for (const char* q = p_; q < end_ && got.size() < 20 && *q != '\n' && *q != '\r'; ++q)
    got += (static_cast<unsigned char>(*q) >= 32 && static_cast<unsigned char>(*q) < 127) ? *q : '?';
  fail(std::string("expected ") + what +
       (got.empty() ? std::string(", found end of line") : ", found '" + got + "'"));
}

void append_number(std::string& out, double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

void append_number(std::string& out, float v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

void append_uint(std::string& out, std::uint64_t v) {
  char buf[24];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

void check_mesh_for_writing(const Mesh& mesh) {
  check_mesh(mesh, "cannot write mesh");
  const std::size_t nv = mesh.vertex_count();
  for (const VertexProperty& p : mesh.vertex_properties)
    if (p.values.size() != nv)
      throw Error("cannot write mesh: vertex property '" + p.name + "' has " +
                  std::to_string(p.values.size()) + " values for " + std::to_string(nv) + " vertices");
}

void check_fits_in_float(const Mesh& mesh, bool with_properties, const char* what) {
  auto refuse = [&](std::size_t vertex, const std::string& value_name, double v) {
    std::string value;
    append_number(value, v);
    throw Error(std::string("cannot write ") + what + ": vertex " + std::to_string(vertex) + " has " +
                value_name + " " + value +
                ", beyond single precision (about 3.4e38); write a PLY with double values (qem --double), "
                "an OBJ or an OFF");
  };
  // Compared before any conversion: a double beyond the float range converted to float is undefined
  // behaviour in C++ (in practice infinity). An infinite or NaN property value stays what it is.
  const double limit = std::numeric_limits<float>::max();
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    if (std::fabs(mesh.positions[i]) > limit) refuse(i / 3, "coordinate", mesh.positions[i]);
  if (with_properties)
    for (const VertexProperty& p : mesh.vertex_properties)
      for (std::size_t i = 0; i < p.values.size(); ++i)
        if (std::isfinite(p.values[i]) && std::fabs(p.values[i]) > limit)
          refuse(i, "property '" + p.name + "' =", p.values[i]);
}

}  // namespace qem::io
