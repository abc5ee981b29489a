// Stanford PLY: ascii, binary_little_endian and binary_big_endian bodies; every scalar type and its
// sized alias; extra properties and elements skipped; header lines with an unknown keyword skipped
// with a warning; faces from a `vertex_indices` / `vertex_index` list (fan-triangulated) or from
// `tristrips` (-1 restarts a strip).
//
// Every count in the header is checked against the bytes that remain before anything is reserved,
// so a header that lies cannot make the reader allocate memory the file does not back. The common
// binary layouts (fixed-size vertex rows, faces "uchar count + int indices") run through tight
// memcpy loops.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "io/io_common.h"
#include "io/ply_types.h"

namespace qem::io {

namespace {

using ply::Type, ply::parse_type, ply::type_size, ply::is_integral;

struct Property {
  std::string name;
  Type type = Type::F32;
  bool is_list = false;
  Type count_type = Type::U8;
  std::size_t line = 0;  ///< its header line, for errors about the property itself
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::size_t header_line = 0;
  std::vector<Property> props;
  bool fixed_size() const {
    return std::none_of(props.begin(), props.end(), [](const Property& p) { return p.is_list; });
  }
  /// Bytes of the smallest possible binary row (lists empty).
  std::uint64_t min_binary_row() const {
    std::uint64_t n = 0;
    for (const Property& p : props) n += type_size(p.is_list ? p.count_type : p.type);
    return n;
  }
};

enum class Encoding { Ascii, Little, Big };

struct Header {
  Encoding encoding = Encoding::Ascii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;
  std::size_t lines = 0;  ///< header lines, so ASCII body line numbers continue from here
};

// --- header --------------------------------------------------------------------------------------

/// At most this many skipped header lines are reported one by one; the rest are counted, so a long
/// run of junk before end_header cannot grow the report without bound.
constexpr std::size_t kMaxHeaderWarnings = 8;

/// Up to 32 characters of a header word for a message, control and non-ASCII bytes shown as '?'
/// (the word comes from a file that may be binary garbage and ends up on a terminal).
// Levenshtein distance of at most two to a keyword that decides the body's layout.
bool near_layout_keyword(std::string_view word) {
  auto distance = [](std::string_view a, std::string_view b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      std::size_t diagonal = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j) {
        const std::size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
        diagonal = up;
      }
    }
    return row[b.size()];
  };
  if (word.size() > 16) return false;
  for (std::string_view k : {"format", "element", "property", "end_header"})
    if (distance(word, k) <= 2) return true;
  return false;
}

std::string shown_word(std::string_view w) {
  std::string s(w.substr(0, 32));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) >= 127) c = '?';
  return s;
}

Header parse_header(std::string_view bytes, const std::string& name, std::vector<std::string>& warnings) {
  Header h;
  std::size_t skipped = 0;
  TextCursor in(bytes, name, 0, false);
  in.skip_blank();
  if (in.word() != "ply") in.fail("not a PLY file (first line must be 'ply')");
  in.next_line();
  bool have_format = false;
  for (;;) {
    if (in.at_end()) in.fail("header has no end_header line");
    in.skip_blank();
    std::string_view kw = in.word();
    if (kw == "end_header") {
      in.skip_blank();
      if (!in.at_line_end()) in.fail("unexpected text after end_header");
      // The body starts right after this line's newline: not after any further whitespace (a
      // binary body may begin with byte 0x0A).
      in.next_line();
      break;
    }
    if (kw == "format") {
      in.skip_blank();
      std::string_view f = in.word();
      if (f == "ascii")
        h.encoding = Encoding::Ascii;
      else if (f == "binary_little_endian")
        h.encoding = Encoding::Little;
      else if (f == "binary_big_endian")
        h.encoding = Encoding::Big;
      else
        in.fail("unknown PLY format '" + std::string(f) + "'");
      have_format = true;
    } else if (kw == "element") {
      Element e;
      in.skip_blank();
      e.name = std::string(in.word());
      if (e.name.empty()) in.fail("element without a name");
      in.skip_blank();
      long long n;
      if (!in.try_integer(n, false) || n < 0) in.fail_expected("a non-negative element count");
      e.count = static_cast<std::uint64_t>(n);
      e.header_line = in.line();
      h.elements.push_back(std::move(e));
    } else if (kw == "property") {
      if (h.elements.empty()) in.fail("property before any element");
      Property p;
      in.skip_blank();
      std::string_view t = in.word();
      if (t == "list") {
        p.is_list = true;
        in.skip_blank();
        std::string_view ct = in.word();
        if (!parse_type(ct, p.count_type)) in.fail("unknown PLY type '" + std::string(ct) + "'");
        if (!is_integral(p.count_type)) in.fail("list count type must be an integer type");
        in.skip_blank();
        t = in.word();
      }
      if (!parse_type(t, p.type)) in.fail("unknown PLY type '" + std::string(t) + "'");
      in.skip_blank();
      p.name = std::string(in.word());
      if (p.name.empty()) in.fail("property without a name");
      p.line = in.line();
      h.elements.back().props.push_back(std::move(p));
    } else if (kw == "comment" || kw == "obj_info" || kw.empty()) {
      // ignored
    } else {
      // Free text without `comment`, as old exporters wrote (Blender 2.4x: "Created by Blender3D
      // 247 - www.blender.org, ..."); assimp and MeshLab skip such lines too. The layout comes only
      // from format / element / property lines, which are never skipped (a malformed one is still
      // an error). A word within two letters of one of them is taken for a misspelling and refused:
      // skipping it would read the body with a wrong layout.
      if (near_layout_keyword(kw))
        fail_line(name, in.line(), "unknown PLY header keyword '" + shown_word(kw) + "' (a misspelled layout keyword?)");
      if (++skipped <= kMaxHeaderWarnings)
        warnings.push_back(
            at_line(name, in.line(), "unknown PLY header keyword '" + shown_word(kw) + "', line skipped"));
    }
    in.next_line();
  }
  if (skipped > kMaxHeaderWarnings)
    warnings.push_back(name + ": " + std::to_string(skipped - kMaxHeaderWarnings) +
                       " more header lines with an unknown keyword skipped");
  if (!have_format) fail(name, "PLY header has no format line");
  h.body_offset = static_cast<std::size_t>(in.pos() - bytes.data());
  h.lines = in.line();
  return h;
}

// --- binary scalar access ------------------------------------------------------------------------

template <class T>
inline T load(const unsigned char* p, bool swap) {
  T v;
  if constexpr (sizeof(T) == 1) {
    std::memcpy(&v, p, 1);
  } else {
    unsigned char b[sizeof(T)];
    std::memcpy(b, p, sizeof(T));
    if (swap) std::reverse(b, b + sizeof(T));
    std::memcpy(&v, b, sizeof(T));
  }
  return v;
}

inline double load_as_double(const unsigned char* p, Type t, bool swap) {
  switch (t) {
    case Type::I8:
      return load<std::int8_t>(p, swap);
    case Type::U8:
      return load<std::uint8_t>(p, swap);
    case Type::I16:
      return load<std::int16_t>(p, swap);
    case Type::U16:
      return load<std::uint16_t>(p, swap);
    case Type::I32:
      return load<std::int32_t>(p, swap);
    case Type::U32:
      return load<std::uint32_t>(p, swap);
    case Type::F32:
      return load<float>(p, swap);
    case Type::F64:
      return load<double>(p, swap);
  }
  return 0;
}

/// Integer value of a count or an index; float types must hold a whole number.
inline bool load_as_int(const unsigned char* p, Type t, bool swap, long long& out) {
  switch (t) {
    case Type::I8:
      out = load<std::int8_t>(p, swap);
      return true;
    case Type::U8:
      out = load<std::uint8_t>(p, swap);
      return true;
    case Type::I16:
      out = load<std::int16_t>(p, swap);
      return true;
    case Type::U16:
      out = load<std::uint16_t>(p, swap);
      return true;
    case Type::I32:
      out = load<std::int32_t>(p, swap);
      return true;
    case Type::U32:
      out = load<std::uint32_t>(p, swap);
      return true;
    case Type::F32:
    case Type::F64: {
      double d = load_as_double(p, t, swap);
      if (!(d >= -9.2e18 && d <= 9.2e18) || d != static_cast<double>(static_cast<long long>(d))) return false;
      out = static_cast<long long>(d);
      return true;
    }
  }
  return false;
}

// --- the body reader -----------------------------------------------------------------------------

/// Reads one value at a time from either an ASCII or a binary body, with bounds checks; errors name
/// the element and its index (binary) or the line (ASCII).
class BodyReader {
 public:
  BodyReader(std::string_view body, const Header& h, const std::string& name)
      : text_(body, name, 0, false, h.lines),
        p_(reinterpret_cast<const unsigned char*>(body.data())),
        end_(p_ + body.size()),
        name_(name),
        ascii_(h.encoding == Encoding::Ascii),
        swap_((h.encoding == Encoding::Big) == (std::endian::native == std::endian::little)) {}

  bool ascii() const { return ascii_; }
  const std::string& name() const { return name_; }
  bool swap() const { return swap_; }
  std::uint64_t remaining() const {
    return ascii_ ? static_cast<std::uint64_t>(text_end() - text_.pos())
                  : static_cast<std::uint64_t>(end_ - p_);
  }
  const unsigned char* ptr() const { return p_; }
  void advance(std::size_t n) { p_ += n; }

  void set_context(const Element* e, std::uint64_t index) {
    elem_ = e;
    index_ = index;
  }
  [[noreturn]] void fail(const std::string& what) const {
    if (ascii_) text_.fail(what);
    fail_element(name_, elem_ ? elem_->name : std::string_view("element"), index_, what);
  }

  double real(Type t) {
    if (ascii_) {
      if (!text_.skip_space()) fail("unexpected end of file (the header declares more data)");
      if (t == Type::F32) {
        float f;
        if (!text_.try_number(f)) fail_expected_number();
        return f;
      }
      double v;
      if (!text_.try_number(v)) fail_expected_number();
      return v;
    }
    need(type_size(t));
    double v = load_as_double(p_, t, swap_);
    p_ += type_size(t);
    return v;
  }
  long long integer(Type t) {
    long long v = 0;
    if (ascii_) {
      if (!text_.skip_space()) fail("unexpected end of file (the header declares more data)");
      if (!text_.try_integer(v, false)) {
        // An integral value written as a real ("3.0"). The range check comes first: converting a
        // double outside long long's range is undefined behaviour (found by fuzz_ply).
        double d;
        if (!text_.try_number(d) || !(d >= -9.2e18 && d <= 9.2e18) ||
            d != static_cast<double>(static_cast<long long>(d)))
          fail_expected_number();
        v = static_cast<long long>(d);
      }
      return v;
    }
    need(type_size(t));
    if (!load_as_int(p_, t, swap_, v)) fail("expected an integer value");
    p_ += type_size(t);
    return v;
  }
  void skip(Type t) {
    if (ascii_) {
      real(t);
      return;
    }
    need(type_size(t));
    p_ += type_size(t);
  }
  /// Checks that `n` more bytes exist (binary).
  void need(std::uint64_t n) const {
    if (static_cast<std::uint64_t>(end_ - p_) < n) fail("file is truncated (the header declares more data)");
  }
  /// A list count: non-negative and small enough to be backed by the remaining data.
  std::size_t list_count(const Property& p) {
    long long c = integer(p.count_type);
    if (c < 0) fail("negative list count " + std::to_string(c) + " for '" + p.name + "'");
    std::uint64_t min_bytes = ascii_ ? 2 : type_size(p.type);
    if (!fits(static_cast<std::uint64_t>(c), min_bytes, remaining() + 1))
      fail("list count " + std::to_string(c) + " for '" + p.name + "' exceeds the data left in the file");
    return static_cast<std::size_t>(c);
  }
  void skip_property(const Property& p) {
    if (!p.is_list) return skip(p.type);
    std::size_t c = list_count(p);
    if (!ascii_) {
      need(c * type_size(p.type));
      p_ += c * type_size(p.type);
    } else {
      for (std::size_t j = 0; j < c; ++j) skip(p.type);
    }
  }

 private:
  const char* text_end() const { return reinterpret_cast<const char*>(end_); }
  [[noreturn]] void fail_expected_number() const {
    std::string what = "a number";  // fail_expected says "expected "
    if (elem_) what += " in " + elem_->name + " " + std::to_string(index_);
    text_.fail_expected(what.c_str());
  }

  TextCursor text_;
  const unsigned char* p_;
  const unsigned char* end_;
  const std::string& name_;
  bool ascii_;
  bool swap_;
  const Element* elem_ = nullptr;
  std::uint64_t index_ = 0;
};

bool is_index_list(const Property& p) {
  return p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index");
}

/// Where a vertex property goes when it is an attribute component (attribute < 0: it is not).
struct AttributeSlot {
  int attribute = -1;
  std::uint32_t component = 0;
  double scale = 1;  ///< integer colours to [0, 1]
};

/// The names writers use for texture coordinates, most common first: Blender writes `s t`,
/// MeshLab `texture_u texture_v`; all of them are read by Blender, MeshLab and trimesh.
constexpr std::string_view kTexCoordNames[][2] = {
    {"s", "t"}, {"u", "v"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}};

/// Finds normals (nx ny nz), texture coordinates and colours (red green blue [alpha]) among the
/// vertex properties and adds their attributes to `mesh`. Colours must be uchar (0..255), ushort
/// (0..65535) or floating point ([0, 1] as is): an integer of another type has no agreed scale.
std::vector<AttributeSlot> find_attributes(const Element& e, Mesh& mesh, std::size_t n,
                                           const std::string& name) {
  std::vector<AttributeSlot> slots(e.props.size());
  auto find = [&](std::string_view prop) -> int {
    for (std::size_t k = 0; k < e.props.size(); ++k)
      if (!e.props[k].is_list && e.props[k].name == prop && slots[k].attribute < 0)
        return static_cast<int>(k);
    return -1;
  };
  auto add = [&](const char* attr, AttributeKind kind, const std::vector<int>& props) {
    const int a = static_cast<int>(mesh.attributes.size());
    mesh.attributes.push_back(
        {attr, kind, static_cast<std::uint32_t>(props.size()), std::vector<double>(props.size() * n)});
    for (std::size_t c = 0; c < props.size(); ++c) {
      AttributeSlot& s = slots[static_cast<std::size_t>(props[c])];
      s.attribute = a;
      s.component = static_cast<std::uint32_t>(c);
      if (kind != AttributeKind::Color) continue;
      const Property& p = e.props[static_cast<std::size_t>(props[c])];
      if (p.type == Type::U8)
        s.scale = 1.0 / 255;
      else if (p.type == Type::U16)
        s.scale = 1.0 / 65535;
      else if (is_integral(p.type))
        fail_line(name, p.line,
                  "vertex colour property '" + p.name +
                      "' has an integer type other than uchar or ushort "
                      "(its scale is unknown; uchar, ushort, float or double expected)");
    }
  };
  const int nx = find("nx"), ny = find("ny"), nz = find("nz");
  if (nx >= 0 && ny >= 0 && nz >= 0) add("NORMAL", AttributeKind::Normal, {nx, ny, nz});
  for (const auto& pair : kTexCoordNames) {
    const int u = find(pair[0]), v = find(pair[1]);
    if (u >= 0 && v >= 0) {
      add("TEXCOORD_0", AttributeKind::TexCoord, {u, v});
      break;
    }
  }
  const int r = find("red"), g = find("green"), b = find("blue"), alpha = find("alpha");
  if (r >= 0 && g >= 0 && b >= 0)
    add("COLOR_0", AttributeKind::Color,
        alpha >= 0 ? std::vector<int>{r, g, b, alpha} : std::vector<int>{r, g, b});
  return slots;
}

/// Refuses a NaN or infinite attribute value of vertex `i`, like a non-finite coordinate.
void check_attributes_finite(BodyReader& in, const Element& e, const Mesh& mesh, std::size_t i) {
  for (const VertexAttribute& a : mesh.attributes)
    for (std::uint32_t c = 0; c < a.components; ++c)
      if (!std::isfinite(a.values[a.components * i + c])) {
        in.set_context(&e, i);
        in.fail(std::string(a.kind == AttributeKind::Normal     ? "normal"
                            : a.kind == AttributeKind::TexCoord ? "texture coordinate"
                                                                : "colour") +
                " is not finite");
      }
}

/// Reads the vertex element: x, y, z (and, if asked, every other scalar property).
void read_vertices(BodyReader& in, const Element& e, Mesh& mesh, const LoadOptions& options,
                   LoadReport& report) {
  int ix = -1, iy = -1, iz = -1;
  for (std::size_t k = 0; k < e.props.size(); ++k) {
    const Property& p = e.props[k];
    if (p.is_list) continue;
    if (p.name == "x")
      ix = static_cast<int>(k);
    else if (p.name == "y")
      iy = static_cast<int>(k);
    else if (p.name == "z")
      iz = static_cast<int>(k);
  }
  if (ix < 0 || iy < 0 || iz < 0) in.fail("vertex element has no x, y, z properties");
  report.double_precision = e.props[ix].type == Type::F64;

  const std::uint64_t min_row = in.ascii() ? 2 * e.props.size() : e.min_binary_row();
  if (!fits(e.count, min_row, in.remaining() + 1))
    in.fail("header declares " + std::to_string(e.count) + " vertices but the file is too short for them");
  const std::size_t n = static_cast<std::size_t>(e.count);
  mesh.positions.resize(3 * n);
  std::vector<AttributeSlot> attr_slot = options.read_attributes ? find_attributes(e, mesh, n, in.name())
                                                                 : std::vector<AttributeSlot>(e.props.size());
  std::vector<int> prop_slot(e.props.size(), -1);  // index into mesh.vertex_properties
  if (options.keep_vertex_properties)
    for (std::size_t k = 0; k < e.props.size(); ++k) {
      const Property& p = e.props[k];
      if (p.is_list || static_cast<int>(k) == ix || static_cast<int>(k) == iy || static_cast<int>(k) == iz ||
          attr_slot[k].attribute >= 0)  // already an attribute: a second copy would be written twice
        continue;
      prop_slot[k] = static_cast<int>(mesh.vertex_properties.size());
      mesh.vertex_properties.push_back({p.name, std::vector<double>(n)});
    }
  double* pos = mesh.positions.data();

  if (!in.ascii() && e.fixed_size()) {
    // Fixed-size rows: one bounds check for the whole element, then straight loads.
    const std::size_t stride = static_cast<std::size_t>(e.min_binary_row());
    in.need(stride * n);
    std::size_t off[3] = {0, 0, 0};
    std::size_t o = 0;
    std::vector<std::size_t> offsets(e.props.size());
    for (std::size_t k = 0; k < e.props.size(); ++k) {
      offsets[k] = o;
      o += type_size(e.props[k].type);
    }
    off[0] = offsets[ix];
    off[1] = offsets[iy];
    off[2] = offsets[iz];
    const unsigned char* row = in.ptr();
    const Type tx = e.props[ix].type, ty = e.props[iy].type, tz = e.props[iz].type;
    const bool swap = in.swap();
    if (!swap && tx == Type::F32 && ty == Type::F32 && tz == Type::F32) {
      for (std::size_t i = 0; i < n; ++i, row += stride) {
        float x, y, z;
        std::memcpy(&x, row + off[0], 4);
        std::memcpy(&y, row + off[1], 4);
        std::memcpy(&z, row + off[2], 4);
        pos[3 * i] = x;
        pos[3 * i + 1] = y;
        pos[3 * i + 2] = z;
      }
    } else {
      for (std::size_t i = 0; i < n; ++i, row += stride) {
        pos[3 * i] = load_as_double(row + off[0], tx, swap);
        pos[3 * i + 1] = load_as_double(row + off[1], ty, swap);
        pos[3 * i + 2] = load_as_double(row + off[2], tz, swap);
      }
    }
    if (options.keep_vertex_properties)
      for (std::size_t k = 0; k < e.props.size(); ++k)
        if (prop_slot[k] >= 0) {
          double* dst = mesh.vertex_properties[prop_slot[k]].values.data();
          const unsigned char* r = in.ptr() + offsets[k];
          for (std::size_t i = 0; i < n; ++i, r += stride) dst[i] = load_as_double(r, e.props[k].type, swap);
        }
    for (std::size_t k = 0; k < e.props.size(); ++k)
      if (attr_slot[k].attribute >= 0) {
        const AttributeSlot& a = attr_slot[k];
        VertexAttribute& dst = mesh.attributes[static_cast<std::size_t>(a.attribute)];
        const unsigned char* r = in.ptr() + offsets[k];
        for (std::size_t i = 0; i < n; ++i, r += stride)
          dst.values[dst.components * i + a.component] = load_as_double(r, e.props[k].type, swap) * a.scale;
      }
    for (std::size_t i = 0; i < n; ++i) {
      if (!finite3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2])) {
        in.set_context(&e, i);
        in.fail("vertex coordinate is not finite");
      }
      check_attributes_finite(in, e, mesh, i);
    }
    in.advance(stride * n);
    return;
  }

  for (std::size_t i = 0; i < n; ++i) {
    in.set_context(&e, i);
    for (std::size_t k = 0; k < e.props.size(); ++k) {
      const Property& p = e.props[k];
      if (p.is_list) {
        in.skip_property(p);
        continue;
      }
      double v = in.real(p.type);
      if (static_cast<int>(k) == ix)
        pos[3 * i] = v;
      else if (static_cast<int>(k) == iy)
        pos[3 * i + 1] = v;
      else if (static_cast<int>(k) == iz)
        pos[3 * i + 2] = v;
      else if (attr_slot[k].attribute >= 0) {
        VertexAttribute& a = mesh.attributes[static_cast<std::size_t>(attr_slot[k].attribute)];
        a.values[a.components * i + attr_slot[k].component] = v * attr_slot[k].scale;
      } else if (prop_slot[k] >= 0)
        mesh.vertex_properties[prop_slot[k]].values[i] = v;
    }
    if (!finite3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2])) in.fail("vertex coordinate is not finite");
    check_attributes_finite(in, e, mesh, i);
  }
}

/// Fast path for the common binary face layout: fixed-size scalars around one index list whose
/// count is 1 byte and whose items are 4-byte integers. Returns false (nothing consumed) otherwise.
bool read_faces_fast(BodyReader& in, const Element& e, std::size_t list_prop, std::uint64_t nv,
                     PolygonSink& sink) {
  if (in.ascii() || e.props.size() > 16) return false;
  for (std::size_t k = 0; k < e.props.size(); ++k)
    if (k != list_prop && e.props[k].is_list) return false;
  const Property& lp = e.props[list_prop];
  if (type_size(lp.count_type) != 1 || (lp.type != Type::I32 && lp.type != Type::U32)) return false;
  std::size_t pre = 0, post = 0;
  for (std::size_t k = 0; k < e.props.size(); ++k)
    if (k < list_prop)
      pre += type_size(e.props[k].type);
    else if (k > list_prop)
      post += type_size(e.props[k].type);
  const bool swap = in.swap();
  const bool signed_count = lp.count_type == Type::I8;
  const bool signed_index = lp.type == Type::I32;
  const unsigned char* p = in.ptr();
  const unsigned char* end = p + in.remaining();
  const std::size_t n = static_cast<std::size_t>(e.count);
  // Triangles are written straight into the index array. Its first size is what the data can
  // back (a valid face row is at least pre + 1 + 12 + post bytes); polygons grow it as needed.
  std::vector<std::uint32_t>& out = *sink.indices;
  std::size_t w = out.size();
  out.resize(w + 3 * std::min<std::size_t>(n, in.remaining() / (pre + post + 13)));
  auto fail_at = [&](std::size_t i, const std::string& what) {
    out.resize(w);
    in.set_context(&e, i);
    in.fail(what);
  };
  auto check_range = [&](std::size_t i, const std::uint32_t* c, int count) {
    for (int k = 0; k < count; ++k)
      if (c[k] >= nv) {
        long long v = signed_index ? static_cast<long long>(static_cast<std::int32_t>(c[k])) : c[k];
        fail_at(i,
                "vertex index " + std::to_string(v) + " out of range (" + std::to_string(nv) + " vertices)");
      }
  };
  std::uint32_t corners[256];
  for (std::size_t i = 0; i < n; ++i) {
    if (static_cast<std::size_t>(end - p) < pre + 1)
      fail_at(i, "file is truncated (the header declares more faces)");
    p += pre;
    const int c = signed_count ? static_cast<int>(static_cast<std::int8_t>(*p)) : static_cast<int>(*p);
    ++p;
    if (c < 3) fail_at(i, "face with " + std::to_string(c) + " vertices (at least 3 needed)");
    const std::size_t bytes = 4 * static_cast<std::size_t>(c) + post;
    if (static_cast<std::size_t>(end - p) < bytes)
      fail_at(i, "file is truncated (the header declares more faces)");
    const std::size_t need = 3 * static_cast<std::size_t>(c - 2);
    if (w + need > out.size()) out.resize(std::max(2 * out.size(), w + need));
    std::uint32_t* dst = out.data() + w;
    if (c == 3 && !swap) {
      // The common case: one triangle, copied as is. A negative int32 reads as >= 2^31, which is
      // out of range as well.
      std::memcpy(dst, p, 12);
      if ((dst[0] >= nv) | (dst[1] >= nv) | (dst[2] >= nv)) check_range(i, dst, 3);
      w += 3;
    } else {
      std::memcpy(corners, p, 4 * static_cast<std::size_t>(c));
      for (int k = 0; k < c; ++k)
        if (swap) corners[k] = __builtin_bswap32(corners[k]);
      check_range(i, corners, c);
      if (c > 3) ++sink.polygons;
      for (int k = 2; k < c; ++k) {
        *dst++ = corners[0];
        *dst++ = corners[k - 1];
        *dst++ = corners[k];
      }
      w += need;
    }
    p += bytes;
  }
  out.resize(w);
  in.advance(static_cast<std::size_t>(p - in.ptr()));
  return true;
}

/// Reads a face element (vertex_indices list) or a tristrips element.
/// Face colours read as materials: each distinct colour is one material named "rgb(R,G,B)" (bytes),
/// in order of first use; the writer turns such materials back into face colours.
struct FaceColours {
  int channel[3] = {-1, -1, -1};  ///< the red, green, blue properties of the face element
  std::vector<std::uint32_t>* face_materials = nullptr;
  std::vector<std::string>* names = nullptr;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> index;  ///< (packed rgb, material), unsorted: few

  /// Finds red, green and blue among `e`'s scalar properties; false when any is missing.
  bool find(const Element& e, const std::string& name) {
    const char* names_rgb[3] = {"red", "green", "blue"};
    for (int c = 0; c < 3; ++c)
      for (std::size_t k = 0; k < e.props.size() && channel[c] < 0; ++k)
        if (!e.props[k].is_list && e.props[k].name == names_rgb[c]) channel[c] = static_cast<int>(k);
    if (channel[0] < 0 || channel[1] < 0 || channel[2] < 0) return false;
    for (int c : channel) {
      const Property& p = e.props[static_cast<std::size_t>(c)];
      if (p.type != Type::U8 && is_integral(p.type))
        fail_line(name, p.line,
                  "face colour property '" + p.name +
                      "' has an integer type other than uchar (uchar, float or "
                      "double expected)");
    }
    return true;
  }
  /// The material of a face whose colour is `rgb` (bytes), added if new.
  std::uint32_t material(const std::uint8_t rgb[3]) {
    const std::uint32_t key = std::uint32_t{rgb[0]} << 16 | std::uint32_t{rgb[1]} << 8 | rgb[2];
    for (const auto& [k, m] : index)
      if (k == key) return m;
    const auto m = static_cast<std::uint32_t>(names->size());
    names->push_back("rgb(" + std::to_string(rgb[0]) + "," + std::to_string(rgb[1]) + "," +
                     std::to_string(rgb[2]) + ")");
    index.emplace_back(key, m);
    return m;
  }
};

/// A colour channel as a byte: uchar as is, a real in [0, 1] scaled; clamped and rounded (an
/// ASCII file may hold 300 in a uchar).
std::uint8_t channel_byte(double v, Type t) {
  double x = t == Type::U8 ? v / 255 : v;
  x = x > 0 ? (x < 1 ? x : 1) : 0;
  return static_cast<std::uint8_t>(x * 255 + 0.5);
}

void read_faces(BodyReader& in, const Element& e, std::uint64_t nv, bool strips, PolygonSink& sink,
                FaceColours* colours = nullptr) {
  std::size_t list_prop = e.props.size();
  for (std::size_t k = 0; k < e.props.size(); ++k)
    if (is_index_list(e.props[k])) {
      list_prop = k;
      break;
    }
  if (list_prop == e.props.size()) {
    in.set_context(&e, 0);
    in.fail("element '" + e.name + "' has no vertex_indices list property");
  }
  const std::uint64_t min_row = in.ascii() ? 2 * e.props.size() : e.min_binary_row();
  if (!fits(e.count, min_row, in.remaining() + 1))
    in.fail("header declares " + std::to_string(e.count) + " " + e.name +
            " elements but the file is too short for them");
  if (!strips && !colours && read_faces_fast(in, e, list_prop, nv, sink)) return;

  std::vector<std::uint32_t> corners;
  const Property& lp = e.props[list_prop];
  for (std::uint64_t i = 0; i < e.count; ++i) {
    in.set_context(&e, i);
    const std::size_t before = sink.indices->size();
    std::uint8_t rgb[3] = {0, 0, 0};
    for (std::size_t k = 0; k < e.props.size(); ++k) {
      if (k != list_prop) {
        int c = 0;
        while (colours && c < 3 && colours->channel[c] != static_cast<int>(k)) ++c;
        if (colours && c < 3) {
          const double v = in.real(e.props[k].type);
          if (!std::isfinite(v)) in.fail("face colour is not finite");
          rgb[c] = channel_byte(v, e.props[k].type);
        } else {
          in.skip_property(e.props[k]);
        }
        continue;
      }
      std::size_t c = in.list_count(lp);
      if (!strips && c < 3) in.fail("face with " + std::to_string(c) + " vertices (at least 3 needed)");
      corners.clear();
      for (std::size_t j = 0; j < c; ++j) {
        long long v = in.integer(lp.type);
        if (strips && v == -1) {
          corners.push_back(0xFFFFFFFFu);
          continue;
        }
        if (v < 0 || static_cast<std::uint64_t>(v) >= nv)
          in.fail("vertex index " + std::to_string(v) + " out of range (" + std::to_string(nv) +
                  " vertices)");
        corners.push_back(static_cast<std::uint32_t>(v));
      }
      if (!strips) {
        sink.add(corners.data(), corners.size());
        continue;
      }
      // Triangle strip: triangle j uses corners j, j+1, j+2, every other one flipped so all keep
      // the orientation of the first; -1 ends a strip and starts the next.
      std::size_t start = 0;
      for (std::size_t j = 0; j <= corners.size(); ++j) {
        if (j < corners.size() && corners[j] != 0xFFFFFFFFu) continue;
        for (std::size_t t = start; t + 2 < j; ++t) {
          std::uint32_t a = corners[t], b = corners[t + 1], c3 = corners[t + 2];
          if ((t - start) % 2 == 1) std::swap(a, b);
          sink.indices->push_back(a);
          sink.indices->push_back(b);
          sink.indices->push_back(c3);
        }
        start = j + 1;
      }
    }
    if (colours)
      colours->face_materials->insert(colours->face_materials->end(), (sink.indices->size() - before) / 3,
                                      colours->material(rgb));
  }
}

void skip_element(BodyReader& in, const Element& e) {
  if (e.props.empty()) return;  // rows of nothing: no data, whatever the count says
  const std::uint64_t min_row = in.ascii() ? 2 * e.props.size() : e.min_binary_row();
  if (!fits(e.count, min_row, in.remaining() + 1))
    in.fail("header declares " + std::to_string(e.count) + " " + e.name +
            " elements but the file is too short for them");
  if (!in.ascii() && e.fixed_size()) {
    in.set_context(&e, 0);
    in.need(e.count * min_row);  // no overflow: checked by fits() above
    in.advance(static_cast<std::size_t>(e.count * min_row));
    return;
  }
  for (std::uint64_t i = 0; i < e.count; ++i) {
    in.set_context(&e, i);
    for (const Property& p : e.props) in.skip_property(p);
  }
}

}  // namespace

namespace {

/// Gives the triangles of a face element without colours, read after a coloured one, the material
/// "rgb(0,0,0)", so face_materials stays one per face.
void pad_materials(Mesh& mesh) {
  if (mesh.face_materials.empty() || mesh.face_materials.size() == mesh.face_count()) return;
  const std::string black = "rgb(0,0,0)";
  auto it = std::find(mesh.material_names.begin(), mesh.material_names.end(), black);
  const auto m = static_cast<std::uint32_t>(it - mesh.material_names.begin());
  if (it == mesh.material_names.end()) mesh.material_names.push_back(black);
  mesh.face_materials.resize(mesh.face_count(), m);
}

}  // namespace

Mesh parse_ply(std::string_view bytes, const std::string& name, const LoadOptions& options,
               LoadReport& report) {
  if (bytes.empty()) fail(name, "empty file");
  Header h = parse_header(bytes, name, report.warnings);
  report.format = FileFormat::Ply;
  report.binary = h.encoding != Encoding::Ascii;

  const Element* vertex = nullptr;
  for (const Element& e : h.elements)
    if (e.name == "vertex") {
      if (vertex) fail_line(name, e.header_line, "second vertex element");
      vertex = &e;
    }
  if (!vertex) fail(name, "PLY header declares no vertex element");
  if (vertex->count > 0xFFFFFFFFull)
    fail_line(name, vertex->header_line, "too many vertices for 32-bit indices");
  const std::uint64_t nv = vertex->count;

  Mesh mesh;
  PolygonSink sink{&mesh.indices};
  BodyReader in(bytes.substr(h.body_offset), h, name);
  for (const Element& e : h.elements) {
    in.set_context(&e, 0);
    if (&e == vertex)
      read_vertices(in, e, mesh, options, report);
    else if (e.name == "face") {
      // Face colours become materials (one per distinct colour): the faces keep their colour
      // through a write, and a colour boundary is a seam to the simplifier, as a material's is.
      FaceColours colours;
      colours.face_materials = &mesh.face_materials;
      colours.names = &mesh.material_names;
      const bool coloured = options.read_attributes && mesh.face_materials.empty() && colours.find(e, name);
      const std::size_t before = mesh.face_count();
      read_faces(in, e, nv, false, sink, coloured ? &colours : nullptr);
      if (coloured && before > 0) {
        // The triangles of earlier face elements had no colour: black, the colour of none.
        const std::uint8_t black[3] = {0, 0, 0};
        mesh.face_materials.insert(mesh.face_materials.begin(), before, colours.material(black));
      }
      pad_materials(mesh);
    } else if (e.name == "tristrips") {
      read_faces(in, e, nv, true, sink);
      pad_materials(mesh);
    } else
      skip_element(in, e);
  }
  if (mesh.indices.empty()) fail(name, "no faces");
  report.polygons_triangulated = sink.polygons;
  return mesh;
}

// --- writer --------------------------------------------------------------------------------------

namespace {

template <class T>
void put(std::string& out, T v) {
  static_assert(std::endian::native == std::endian::little || std::endian::native == std::endian::big);
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(b, b + sizeof(T));
  out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

bool valid_property_name(const std::string& s) {
  if (s.empty()) return false;
  for (unsigned char c : s)
    if (c <= 32 || c >= 127) return false;
  return true;
}

/// The attributes a PLY holds, each written as its conventional properties: the first normal
/// (nx ny nz), texture coordinate (s t, Blender's names) and colour (red green blue [alpha] as
/// uchar, what MeshLab and Blender read). Others are not written.
struct PlyAttributes {
  const VertexAttribute* normal;
  const VertexAttribute* texcoord;
  const VertexAttribute* colour;
  explicit PlyAttributes(const Mesh& m)
      : normal(m.find_attribute(AttributeKind::Normal)),
        texcoord(m.find_attribute(AttributeKind::TexCoord)),
        colour(m.find_attribute(AttributeKind::Color)) {}
  std::uint32_t colour_channels() const { return colour ? (colour->components >= 4 ? 4 : 3) : 0; }
  /// True when a vertex property of this name would repeat an attribute's property.
  bool claims(const std::string& p) const {
    if (normal && (p == "nx" || p == "ny" || p == "nz")) return true;
    if (texcoord && (p == "s" || p == "t")) return true;
    return colour && (p == "red" || p == "green" || p == "blue" || (colour_channels() == 4 && p == "alpha"));
  }
};

/// The byte colour of each material when every material is named "rgb(R,G,B)" (as the reader
/// names face colours), else empty: other materials (OBJ's named ones) have no PLY form.
std::vector<std::array<std::uint8_t, 3>> face_colours(const Mesh& m) {
  std::vector<std::array<std::uint8_t, 3>> colours;
  if (m.face_materials.empty()) return colours;
  for (const std::string& n : m.material_names) {
    unsigned rgb[3];
    int used = 0;
    if (std::sscanf(n.c_str(), "rgb(%u,%u,%u)%n", &rgb[0], &rgb[1], &rgb[2], &used) != 3 ||
        static_cast<std::size_t>(used) != n.size() || rgb[0] > 255 || rgb[1] > 255 || rgb[2] > 255)
      return {};
    colours.push_back({std::uint8_t(rgb[0]), std::uint8_t(rgb[1]), std::uint8_t(rgb[2])});
  }
  for (std::uint32_t f : m.face_materials)
    if (f >= colours.size()) return {};
  return colours;
}

/// A [0, 1] colour value as a byte, clamped and rounded.
std::uint8_t colour_byte(double v) {
  const double x = v < 0 ? 0 : v > 1 ? 1 : v;
  return static_cast<std::uint8_t>(x * 255 + 0.5);
}

/// Component k of vertex i of `a`, 0 where the attribute has fewer components.
double component(const VertexAttribute& a, std::size_t i, std::uint32_t k) {
  return k < a.components ? a.values[a.components * i + k] : 0.0;
}

}  // namespace

std::string write_ply(const Mesh& mesh, bool binary, bool double_precision) {
  const std::size_t nv = mesh.vertex_count(), nf = mesh.face_count();
  const PlyAttributes attrs(mesh);
  for (const VertexProperty& p : mesh.vertex_properties)
    if (!valid_property_name(p.name) || p.name == "x" || p.name == "y" || p.name == "z")
      throw Error("cannot write PLY: invalid vertex property name '" + p.name + "'");
  std::vector<const VertexProperty*> props;
  for (const VertexProperty& p : mesh.vertex_properties)
    if (!attrs.claims(p.name)) props.push_back(&p);
  if (!double_precision) {
    check_fits_in_float(mesh, true, "PLY with float values");
    for (const VertexAttribute* a : {attrs.normal, attrs.texcoord})
      if (a)
        for (std::size_t i = 0; i < a->values.size(); ++i)
          if (std::fabs(a->values[i]) > std::numeric_limits<float>::max())
            throw Error("cannot write PLY with float values: vertex " + std::to_string(i / a->components) +
                        " has attribute '" + a->name +
                        "' beyond single precision; write a PLY with double values (qem --double)");
  }
  const char* type = double_precision ? "double" : "float";
  std::string out;
  out += "ply\nformat ";
  out += binary ? "binary_little_endian" : "ascii";
  out += " 1.0\ncomment written by qem\nelement vertex ";
  append_uint(out, nv);
  out += '\n';
  for (const char* axis : {"x", "y", "z"}) out += std::string("property ") + type + " " + axis + "\n";
  if (attrs.normal)
    for (const char* c : {"nx", "ny", "nz"}) out += std::string("property ") + type + " " + c + "\n";
  if (attrs.texcoord)
    for (const char* c : {"s", "t"}) out += std::string("property ") + type + " " + c + "\n";
  const char* channels[] = {"red", "green", "blue", "alpha"};
  for (std::uint32_t k = 0; k < attrs.colour_channels(); ++k)
    out += std::string("property uchar ") + channels[k] + "\n";
  for (const VertexProperty* p : props) out += std::string("property ") + type + " " + p->name + "\n";
  out += "element face ";
  append_uint(out, nf);
  out += "\nproperty list uchar int vertex_indices\n";
  const std::vector<std::array<std::uint8_t, 3>> fcol = face_colours(mesh);
  if (!fcol.empty()) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += "end_header\n";

  // One row of real values per vertex, in header order; colours are bytes.
  std::vector<double> row;
  auto fill_row = [&](std::size_t i) {
    row.clear();
    for (int k = 0; k < 3; ++k) row.push_back(mesh.positions[3 * i + k]);
    if (attrs.normal)
      for (std::uint32_t k = 0; k < 3; ++k) row.push_back(component(*attrs.normal, i, k));
    if (attrs.texcoord)
      for (std::uint32_t k = 0; k < 2; ++k) row.push_back(component(*attrs.texcoord, i, k));
  };
  auto colour_at = [&](std::size_t i, std::uint32_t k) {
    // A missing alpha never happens (colour_channels() is 3 then); missing RGB components are 0.
    return colour_byte(component(*attrs.colour, i, k));
  };
  const std::uint32_t nc = attrs.colour_channels();
  if (binary) {
    const std::size_t reals = 3 + (attrs.normal ? 3 : 0) + (attrs.texcoord ? 2 : 0) + props.size();
    out.reserve(out.size() + nv * (reals * (double_precision ? 8 : 4) + nc) + nf * 13);
    for (std::size_t i = 0; i < nv; ++i) {
      fill_row(i);
      for (double v : row) {
        if (double_precision)
          put(out, v);
        else
          put(out, static_cast<float>(v));
      }
      for (std::uint32_t k = 0; k < nc; ++k) out += static_cast<char>(colour_at(i, k));
      for (const VertexProperty* p : props) {
        if (double_precision)
          put(out, p->values[i]);
        else
          put(out, static_cast<float>(p->values[i]));
      }
    }
    for (std::size_t f = 0; f < nf; ++f) {
      out += '\3';
      for (int k = 0; k < 3; ++k) put(out, static_cast<std::int32_t>(mesh.indices[3 * f + k]));
      if (!fcol.empty())
        for (std::uint8_t c : fcol[mesh.face_materials[f]]) out += static_cast<char>(c);
    }
    return out;
  }
  auto number = [&](double v) {
    if (double_precision)
      append_number(out, v);
    else
      append_number(out, static_cast<float>(v));
  };
  for (std::size_t i = 0; i < nv; ++i) {
    fill_row(i);
    for (std::size_t k = 0; k < row.size(); ++k) {
      if (k) out += ' ';
      number(row[k]);
    }
    for (std::uint32_t k = 0; k < nc; ++k) {
      out += ' ';
      append_uint(out, colour_at(i, k));
    }
    for (const VertexProperty* p : props) {
      out += ' ';
      number(p->values[i]);
    }
    out += '\n';
  }
  for (std::size_t f = 0; f < nf; ++f) {
    out += "3 ";
    append_uint(out, mesh.indices[3 * f]);
    out += ' ';
    append_uint(out, mesh.indices[3 * f + 1]);
    out += ' ';
    append_uint(out, mesh.indices[3 * f + 2]);
    if (!fcol.empty())
      for (std::uint8_t c : fcol[mesh.face_materials[f]]) {
        out += ' ';
        append_uint(out, c);
      }
    out += '\n';
  }
  return out;
}

}  // namespace qem::io
