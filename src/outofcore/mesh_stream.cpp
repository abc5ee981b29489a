#include "outofcore/mesh_stream.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <sstream>
#include <vector>

#include "io/ply_types.h"
#include "qem/error.h"

namespace qem::outofcore {
namespace {

using io::ply::Type, io::ply::parse_type, io::ply::type_size;

struct Property {
  std::string name;
  Type type = Type::F32, count_type = Type::U8;
  bool is_list = false;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> props;
  bool fixed_size() const {
    return std::none_of(props.begin(), props.end(), [](const Property& p) { return p.is_list; });
  }
  std::uint64_t row_size() const {
    std::uint64_t n = 0;
    for (const Property& p : props) n += type_size(p.type);
    return n;
  }
};

double load(const unsigned char* p, Type t, bool swap) {
  unsigned char b[8];
  const std::size_t n = type_size(t);
  std::memcpy(b, p, n);
  if (swap) std::reverse(b, b + n);
  switch (t) {
    case Type::I8:
      return double(std::int8_t(b[0]));
    case Type::U8:
      return double(b[0]);
    case Type::I16: {
      std::int16_t v;
      std::memcpy(&v, b, 2);
      return v;
    }
    case Type::U16: {
      std::uint16_t v;
      std::memcpy(&v, b, 2);
      return v;
    }
    case Type::I32: {
      std::int32_t v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case Type::U32: {
      std::uint32_t v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case Type::F32: {
      float v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case Type::F64: {
      double v;
      std::memcpy(&v, b, 8);
      return v;
    }
  }
  return 0;
}

constexpr std::size_t kChunkBytes = std::size_t(8) << 20;
constexpr std::size_t kChunkItems = 1 << 16;

}  // namespace

struct MeshStream::Impl {
  std::string path;
  int fd = -1;
  std::uint64_t size = 0, read_total = 0;
  bool ply = true, swap = false;
  std::vector<Element> elements;
  std::uint64_t body = 0;
  int vertex_element = -1, face_element = -1, face_list = -1;
  int axis[3] = {-1, -1, -1};
  std::uint64_t stl_triangles = 0;

  // The read window: bytes [file_pos, file_pos + (end - 0)) of the file are in buf[0, end).
  std::vector<unsigned char> buf;
  std::uint64_t file_pos = 0;
  std::size_t cur = 0, end = 0;

  [[noreturn]] void fail(const std::string& what) const { throw Error(path + ": " + what); }
  [[noreturn]] void fail_at(const Element& e, std::uint64_t i, const std::string& what) const {
    throw Error(path + ", " + e.name + " " + std::to_string(i) + ": " + what);
  }

  void seek(std::uint64_t offset) {
    file_pos = offset;
    cur = end = 0;
  }
  std::uint64_t offset() const { return file_pos + cur; }

  /// Makes at least k bytes available at buf[cur]; false at the end of the file.
  bool ensure(std::size_t k) {
    if (end - cur >= k) return true;
    if (buf.size() < kChunkBytes) buf.resize(kChunkBytes);
    std::memmove(buf.data(), buf.data() + cur, end - cur);
    file_pos += cur;
    end -= cur;
    cur = 0;
    while (end < k) {
      ssize_t n = ::pread(fd, buf.data() + end, buf.size() - end, off_t(file_pos + end));
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) fail(std::string("cannot read: ") + std::strerror(errno));
      if (n == 0) return false;
      end += std::size_t(n);
      read_total += std::uint64_t(n);
    }
    return true;
  }

  void need(const Element& e, std::uint64_t i, std::size_t k) {
    if (!ensure(k)) fail_at(e, i, "the file ends inside it");
  }

  void parse_ply_header() {
    std::string text;
    text.resize(std::min<std::uint64_t>(size, 1 << 20));
    ssize_t n = ::pread(fd, text.data(), text.size(), 0);
    if (n < 0) fail(std::string("cannot read: ") + std::strerror(errno));
    text.resize(std::size_t(n));
    std::size_t pos = 0, line_no = 0;
    bool have_format = false, ended = false;
    while (pos < text.size()) {
      std::size_t nl = text.find('\n', pos);
      if (nl == std::string::npos) break;
      std::string line = text.substr(pos, nl - pos);
      pos = nl + 1;
      ++line_no;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      std::istringstream in(line);
      std::string kw;
      in >> kw;
      auto bad = [&](const std::string& what) { fail("line " + std::to_string(line_no) + ": " + what); };
      if (line_no == 1) {
        if (kw != "ply") fail("not a PLY file (first line must be 'ply')");
        continue;
      }
      if (kw == "end_header") {
        ended = true;
        break;
      } else if (kw == "format") {
        std::string f;
        in >> f;
        if (f == "binary_little_endian")
          swap = false;
        else if (f == "binary_big_endian")
          swap = true;
        else if (f == "ascii")
          fail(
              "an ASCII PLY is not read in chunks; convert it to binary (qem simplify IN OUT.ply --faces "
              "<its face count>) or give it enough --memory-limit to be read whole");
        else
          bad("unknown PLY format '" + f + "'");
        have_format = true;
      } else if (kw == "element") {
        Element e;
        long long count = -1;
        in >> e.name >> count;
        if (e.name.empty() || count < 0) bad("element needs a name and a non-negative count");
        e.count = std::uint64_t(count);
        elements.push_back(std::move(e));
      } else if (kw == "property") {
        if (elements.empty()) bad("property before any element");
        Property p;
        std::string t;
        in >> t;
        if (t == "list") {
          p.is_list = true;
          std::string ct;
          in >> ct;
          if (!parse_type(ct, p.count_type) || !io::ply::is_integral(p.count_type))
            bad("list count type must be an integer type");
          in >> t;
        }
        if (!parse_type(t, p.type)) bad("unknown PLY type '" + t + "'");
        in >> p.name;
        if (p.name.empty()) bad("property without a name");
        elements.back().props.push_back(p);
      }
      // comment, obj_info and other lines: nothing that changes the layout
    }
    if (!ended) fail("PLY header has no end_header line (within its first MB)");
    if (!have_format) fail("PLY header has no format line");
    body = pos;
    for (std::size_t i = 0; i < elements.size(); ++i) {
      if (elements[i].name == "vertex" && vertex_element < 0) vertex_element = int(i);
      if (elements[i].name == "face" && face_element < 0) face_element = int(i);
    }
    if (vertex_element < 0) fail("PLY header declares no vertex element");
    const Element& v = elements[std::size_t(vertex_element)];
    if (!v.fixed_size()) fail("the vertex element has a list property: not read in chunks");
    for (std::size_t k = 0; k < v.props.size(); ++k)
      for (int a = 0; a < 3; ++a)
        if (v.props[k].name == std::string(1, char('x' + a))) axis[a] = int(k);
    if (axis[0] < 0 || axis[1] < 0 || axis[2] < 0) fail("vertex element has no x, y, z properties");
    if (face_element >= 0) {
      const Element& f = elements[std::size_t(face_element)];
      for (std::size_t k = 0; k < f.props.size(); ++k)
        if (f.props[k].is_list && (f.props[k].name == "vertex_indices" || f.props[k].name == "vertex_index"))
          face_list = int(k);
      if (face_list < 0) fail("element 'face' has no vertex_indices list property");
      if (f.props[std::size_t(face_list)].type == Type::F32 ||
          f.props[std::size_t(face_list)].type == Type::F64)
        fail("vertex_indices must be an integer type");
    }
    if (v.count > 0xffffffffull) fail("more than 2^32 vertices: not supported");
  }

  /// Positions the window at the start of element `target`, skipping the ones before it.
  void go_to_element(int target) {
    seek(body);
    for (int i = 0; i < target; ++i) {
      const Element& e = elements[std::size_t(i)];
      if (e.fixed_size()) {
        const std::uint64_t bytes = e.count * e.row_size();
        if (e.count != 0 && bytes / e.count != e.row_size()) fail("element '" + e.name + "' is too large");
        if (offset() + bytes > size) fail("the file is too short for its " + e.name + " elements");
        seek(offset() + bytes);
        continue;
      }
      for (std::uint64_t r = 0; r < e.count; ++r) skip_row(e, r);
    }
  }

  void skip_row(const Element& e, std::uint64_t r) {
    for (const Property& p : e.props) {
      if (!p.is_list) {
        need(e, r, type_size(p.type));
        cur += type_size(p.type);
        continue;
      }
      need(e, r, type_size(p.count_type));
      const double n = load(&buf[cur], p.count_type, swap);
      cur += type_size(p.count_type);
      if (n < 0) fail_at(e, r, "negative list length");
      const std::size_t bytes = std::size_t(n) * type_size(p.type);
      need(e, r, bytes);
      cur += bytes;
    }
  }
};

MeshStream::MeshStream(const std::string& path) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  if (!streamable_extension(path)) m.fail("only binary PLY and binary STL are read in chunks");
  m.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (m.fd < 0) m.fail(std::string("cannot open: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(m.fd, &st) != 0) m.fail(std::string("cannot read: ") + std::strerror(errno));
  m.size = std::uint64_t(st.st_size);
  std::string ext = path.substr(path.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  m.ply = ext == ".ply";
  if (m.ply) {
    m.parse_ply_header();
    return;
  }
  unsigned char head[84];
  if (m.size < 84 || ::pread(m.fd, head, 84, 0) != 84) m.fail("too short for a binary STL");
  std::uint32_t count;
  std::memcpy(&count, head + 80, 4);
  if (84 + 50ull * count != m.size)
    m.fail(
        "not a binary STL (its size does not match its triangle count); an ASCII STL is not read in "
        "chunks: give it enough --memory-limit to be read whole");
  m.stl_triangles = count;
}

MeshStream::~MeshStream() {
  if (impl_ && impl_->fd >= 0) ::close(impl_->fd);
}

bool MeshStream::indexed() const { return impl_->ply; }
std::uint64_t MeshStream::vertex_count() const {
  return impl_->ply ? impl_->elements[std::size_t(impl_->vertex_element)].count : 3 * impl_->stl_triangles;
}
std::uint64_t MeshStream::face_count() const {
  if (!impl_->ply) return impl_->stl_triangles;
  return impl_->face_element < 0 ? 0 : impl_->elements[std::size_t(impl_->face_element)].count;
}
std::uint64_t MeshStream::file_size() const { return impl_->size; }
std::uint64_t MeshStream::bytes_read() const { return impl_->read_total; }
const std::string& MeshStream::path() const { return impl_->path; }

std::vector<std::string> MeshStream::unread() const {
  const Impl& m = *impl_;
  std::vector<std::string> out;
  if (!m.ply) return out;
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    const Element& element = m.elements[e];
    if (int(e) != m.vertex_element && int(e) != m.face_element) {
      if (element.count > 0) out.push_back(element.name);
      continue;
    }
    for (std::size_t k = 0; k < element.props.size(); ++k) {
      const bool read = int(e) == m.vertex_element
                            ? int(k) == m.axis[0] || int(k) == m.axis[1] || int(k) == m.axis[2]
                            : int(k) == m.face_list;
      if (!read) out.push_back(element.name + " " + element.props[k].name);
    }
  }
  return out;
}

bool MeshStream::float_vertex_layout(std::uint64_t& offset, std::size_t& row, std::size_t at[3]) const {
  const Impl& m = *impl_;
  if (!m.ply || m.swap) return false;
  offset = m.body;
  for (int i = 0; i < m.vertex_element; ++i) {
    const Element& e = m.elements[std::size_t(i)];
    if (!e.fixed_size()) return false;
    offset += e.count * e.row_size();
  }
  const Element& v = m.elements[std::size_t(m.vertex_element)];
  row = std::size_t(v.row_size());
  for (int a = 0; a < 3; ++a) {
    if (v.props[std::size_t(m.axis[a])].type != Type::F32) return false;
    at[a] = 0;
    for (int k = 0; k < m.axis[a]; ++k) at[a] += type_size(v.props[std::size_t(k)].type);
  }
  return offset + v.count * row <= m.size;
}

bool MeshStream::streamable_extension(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".ply" || ext == ".stl";
}

void MeshStream::read_vertices(const std::function<void(const double*, std::size_t)>& chunk) {
  Impl& m = *impl_;
  m.go_to_element(m.vertex_element);
  const Element& e = m.elements[std::size_t(m.vertex_element)];
  std::size_t at[3];
  Type type[3];
  for (int a = 0; a < 3; ++a) {
    at[a] = 0;
    for (int k = 0; k < m.axis[a]; ++k) at[a] += type_size(e.props[std::size_t(k)].type);
    type[a] = e.props[std::size_t(m.axis[a])].type;
  }
  const std::size_t row = std::size_t(e.row_size());
  std::vector<double> xyz;
  xyz.reserve(3 * kChunkItems);
  const bool floats = !m.swap && type[0] == Type::F32 && type[1] == Type::F32 && type[2] == Type::F32;
  for (std::uint64_t i = 0; i < e.count; ++i) {
    m.need(e, i, row);
    const unsigned char* p = &m.buf[m.cur];
    for (int a = 0; a < 3; ++a) {
      float f;
      if (floats) std::memcpy(&f, p + at[a], 4);  // the common layout, without load()'s switch
      const double v = floats ? double(f) : load(p + at[a], type[a], m.swap);
      if (!std::isfinite(v)) m.fail_at(e, i, "coordinate is not finite");
      xyz.push_back(v);
    }
    m.cur += row;
    if (xyz.size() == 3 * kChunkItems) {
      chunk(xyz.data(), kChunkItems);
      xyz.clear();
    }
  }
  if (!xyz.empty()) chunk(xyz.data(), xyz.size() / 3);
}

void MeshStream::read_triangles(const std::function<void(const std::uint32_t*, std::size_t)>& chunk) {
  Impl& m = *impl_;
  if (m.face_element < 0) return;
  m.go_to_element(m.face_element);
  const Element& e = m.elements[std::size_t(m.face_element)];
  const std::uint64_t nv = vertex_count();
  std::vector<std::uint32_t> tri, poly;
  tri.reserve(3 * kChunkItems + 3 * 256);
  // The common layout (one list of uchar count and 32-bit indices, little endian): a triangle's
  // row is read with one copy; any other row (a polygon, other properties) takes the general way.
  const bool simple = e.props.size() == 1 && e.props[0].count_type == Type::U8 &&
                      (e.props[0].type == Type::I32 || e.props[0].type == Type::U32) && !m.swap;
  for (std::uint64_t i = 0; i < e.count; ++i) {
    if (simple && m.ensure(13) && m.buf[m.cur] == 3) {
      std::uint32_t v[3];
      std::memcpy(v, &m.buf[m.cur + 1], 12);
      for (int c = 0; c < 3; ++c)
        if (v[c] >= nv)  // an int32 below 0 reads as a large uint32
          m.fail_at(e, i,
                    "vertex index " +
                        std::to_string(e.props[0].type == Type::I32 ? std::int64_t(std::int32_t(v[c]))
                                                                    : std::int64_t(v[c])) +
                        " out of range (" + std::to_string(nv) + " vertices)");
      m.cur += 13;
      tri.insert(tri.end(), {v[0], v[1], v[2]});
      if (tri.size() >= 3 * kChunkItems) {
        chunk(tri.data(), tri.size() / 3);
        tri.clear();
      }
      continue;
    }
    for (std::size_t k = 0; k < e.props.size(); ++k) {
      const Property& p = e.props[k];
      if (int(k) != m.face_list) {
        if (!p.is_list) {
          m.need(e, i, type_size(p.type));
          m.cur += type_size(p.type);
        } else {
          m.need(e, i, type_size(p.count_type));
          const double n = load(&m.buf[m.cur], p.count_type, m.swap);
          m.cur += type_size(p.count_type);
          if (n < 0) m.fail_at(e, i, "negative list length");
          m.need(e, i, std::size_t(n) * type_size(p.type));
          m.cur += std::size_t(n) * type_size(p.type);
        }
        continue;
      }
      m.need(e, i, type_size(p.count_type));
      const double n = load(&m.buf[m.cur], p.count_type, m.swap);
      m.cur += type_size(p.count_type);
      if (n < 0) m.fail_at(e, i, "negative list length");
      const std::size_t corners = std::size_t(n), is = type_size(p.type);
      m.need(e, i, corners * is);
      poly.clear();
      for (std::size_t c = 0; c < corners; ++c) {
        const double v = load(&m.buf[m.cur + c * is], p.type, m.swap);
        if (v < 0 || v >= double(nv))
          m.fail_at(e, i,
                    "vertex index " + std::to_string(static_cast<long long>(v)) + " out of range (" +
                        std::to_string(nv) + " vertices)");
        poly.push_back(std::uint32_t(v));
      }
      m.cur += corners * is;
      for (std::size_t c = 2; c < corners; ++c) tri.insert(tri.end(), {poly[0], poly[c - 1], poly[c]});
    }
    if (tri.size() >= 3 * kChunkItems) {
      chunk(tri.data(), tri.size() / 3);
      tri.clear();
    }
  }
  if (!tri.empty()) chunk(tri.data(), tri.size() / 3);
}

void MeshStream::read_soup(const std::function<void(const double*, std::size_t)>& chunk) {
  Impl& m = *impl_;
  m.seek(84);
  Element e{"triangle", m.stl_triangles, {}};
  std::vector<double> xyz;
  xyz.reserve(9 * kChunkItems);
  for (std::uint64_t i = 0; i < m.stl_triangles; ++i) {
    m.need(e, i, 50);
    const unsigned char* p = &m.buf[m.cur] + 12;  // after the facet normal
    for (int k = 0; k < 9; ++k) {
      const double v = load(p + 4 * k, Type::F32, false);
      if (!std::isfinite(v)) m.fail_at(e, i, "coordinate is not finite");
      xyz.push_back(v);
    }
    m.cur += 50;
    if (xyz.size() == 9 * kChunkItems) {
      chunk(xyz.data(), kChunkItems);
      xyz.clear();
    }
  }
  if (!xyz.empty()) chunk(xyz.data(), xyz.size() / 9);
}

}  // namespace qem::outofcore
