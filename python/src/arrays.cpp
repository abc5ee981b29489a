#include "arrays.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

namespace qem::python {
namespace {

std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// np.asarray: lists and other sequences are accepted; arrays pass through without a copy.
py::array as_array(py::handle obj, const char* name) {
  if (obj.is_none()) throw py::value_error(std::string(name) + ": expected an array, got None");
  py::object a;
  try {
    a = py::module_::import("numpy").attr("asarray")(obj);
  } catch (py::error_already_set& e) {
    throw py::value_error(std::string(name) + ": not convertible to an array (" + e.what() + ")");
  }
  return py::reinterpret_borrow<py::array>(a);
}

char kind_of(const py::array& a) { return a.dtype().kind(); }

void require_rows_of_3(const py::array& a, const char* name, const char* what) {
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(std::string(name) + ": expected shape (n, 3) of " + what + ", got " + shape_of(a));
}

// The buffer can be read in place as T: same dtype (native byte order), C order, aligned.
template <class T>
bool viewable_as(const py::array& a) {
  constexpr int kAligned = 0x0100;  // NPY_ARRAY_ALIGNED
  return py::isinstance<py::array_t<T, py::array::c_style>>(a) && (a.flags() & kAligned) != 0;
}

// A view of a vector's buffer owned by a capsule: numpy frees the vector with the array.
template <class T, class Out = T>
py::array_t<Out> take(std::vector<T>&& v, std::size_t columns) {
  static_assert(sizeof(T) == sizeof(Out));
  auto* owned = new std::vector<T>(std::move(v));
  py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  const py::ssize_t rows = py::ssize_t(owned->size() / columns);
  std::vector<py::ssize_t> shape = columns == 1 ? std::vector<py::ssize_t>{rows}
                                                : std::vector<py::ssize_t>{rows, py::ssize_t(columns)};
  return py::array_t<Out>(shape, reinterpret_cast<const Out*>(owned->data()), free_when_done);
}

}  // namespace

Positions positions_from(py::handle obj, const char* name) {
  py::array a = as_array(obj, name);
  require_rows_of_3(a, name, "x, y, z coordinates");
  const char k = kind_of(a);
  if (k != 'f' && k != 'i' && k != 'u')
    throw py::value_error(std::string(name) + ": expected a float array, got dtype " +
                          py::str(a.dtype()).cast<std::string>());
  Positions p;
  if (viewable_as<double>(a)) {
    p.keep_alive = a;
    p.data = std::span<const double>(static_cast<const double*>(a.data()), std::size_t(a.size()));
  } else {
    // Any other dtype or layout (float32, Fortran order, strided slices): one converting copy.
    auto c = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
    if (!c) throw py::error_already_set();
    p.copy.assign(c.data(), c.data() + c.size());
    p.data = p.copy;
  }
  for (std::size_t i = 0; i < p.data.size(); ++i)
    if (!std::isfinite(p.data[i]))
      throw py::value_error(std::string(name) + "[" + std::to_string(i / 3) + "] has a non-finite coordinate (" +
                            py::repr(py::float_(p.data[i])).cast<std::string>() + ")");
  return p;
}

namespace {

template <class T>
void check_range(const T* data, std::size_t n, const char* name, std::size_t vertex_count) {
  for (std::size_t i = 0; i < n; ++i) {
    const T v = data[i];
    bool bad;
    if constexpr (std::is_signed_v<T>)
      bad = v < 0 || std::uint64_t(v) >= vertex_count;
    else
      bad = std::uint64_t(v) >= vertex_count;
    if (bad)
      throw py::value_error(std::string(name) + "[" + std::to_string(i / 3) + "] has index " + std::to_string(v) +
                            ", out of range for " + std::to_string(vertex_count) + " vertices");
  }
}

}  // namespace

Indices indices_from(py::handle obj, const char* name, std::size_t vertex_count) {
  py::array a = as_array(obj, name);
  require_rows_of_3(a, name, "vertex indices");
  const char k = kind_of(a);
  if (k != 'i' && k != 'u')
    throw py::value_error(std::string(name) + ": expected an integer array, got dtype " +
                          py::str(a.dtype()).cast<std::string>());
  Indices out;
  const std::size_t n = std::size_t(a.size());
  if (viewable_as<std::int32_t>(a) || viewable_as<std::uint32_t>(a)) {
    // int32 and uint32 have the library's layout: checked in place (a negative int32 would read
    // as a huge uint32, so it is checked as signed), then viewed as uint32.
    if (k == 'i')
      check_range(static_cast<const std::int32_t*>(a.data()), n, name, vertex_count);
    else
      check_range(static_cast<const std::uint32_t*>(a.data()), n, name, vertex_count);
    out.keep_alive = a;
    out.data = std::span<const std::uint32_t>(static_cast<const std::uint32_t*>(a.data()), n);
    return out;
  }
  // Other widths or layouts: through int64 (or uint64), checked, then narrowed.
  if (k == 'u' && a.itemsize() == 8) {
    auto c = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    if (!c) throw py::error_already_set();
    check_range(c.data(), n, name, vertex_count);
    out.copy.assign(c.data(), c.data() + n);
  } else {
    auto c = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    if (!c) throw py::error_already_set();
    check_range(c.data(), n, name, vertex_count);
    out.copy.assign(c.data(), c.data() + n);
  }
  out.data = out.copy;
  return out;
}

std::vector<double> values_from(py::handle obj, const std::string& name, std::size_t rows, std::uint32_t& columns) {
  py::array a = as_array(obj, name.c_str());
  const char k = kind_of(a);
  if (k != 'f' && k != 'i' && k != 'u' && k != 'b')
    throw py::value_error(name + ": expected a numeric array, got dtype " + py::str(a.dtype()).cast<std::string>());
  if (a.ndim() == 1) {
    columns = 1;
  } else if (a.ndim() == 2 && a.shape(1) >= 1 && a.shape(1) <= 4) {
    columns = std::uint32_t(a.shape(1));
  } else {
    throw py::value_error(name + ": expected shape (n,) or (n, k) with k in 1..4, got " + shape_of(a));
  }
  if (std::size_t(a.shape(0)) != rows)
    throw py::value_error(name + ": has " + std::to_string(a.shape(0)) + " rows, expected one per vertex (" +
                          std::to_string(rows) + ")");
  auto c = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!c) throw py::error_already_set();
  std::vector<double> v(c.data(), c.data() + c.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw py::value_error(name + "[" + std::to_string(i / columns) + "] has a non-finite value");
  return v;
}

py::array_t<double> take_positions(std::vector<double>&& v, std::size_t columns) {
  return take<double>(std::move(v), columns);
}

py::array take_indices(std::vector<std::uint32_t>&& v, std::size_t columns, std::size_t vertex_count) {
  if (vertex_count <= std::size_t(std::numeric_limits<std::int32_t>::max()))
    return take<std::uint32_t, std::int32_t>(std::move(v), columns);
  std::vector<py::ssize_t> shape{py::ssize_t(v.size() / columns)};
  if (columns > 1) shape.push_back(py::ssize_t(columns));
  py::array_t<std::int64_t> wide(shape);
  std::copy(v.begin(), v.end(), wide.mutable_data());
  return wide;
}

py::array_t<std::int32_t> take_map(std::vector<std::uint32_t>&& v) {
  // kUnmapped (0xffffffff) reads as -1 in two's complement int32: the numpy convention for "none".
  return take<std::uint32_t, std::int32_t>(std::move(v), 1);
}

MeshArrays mesh_from(py::handle obj, const char* name) {
  py::object vertices, faces;
  if (py::isinstance<py::tuple>(obj) || py::isinstance<py::list>(obj)) {
    py::sequence s = py::reinterpret_borrow<py::sequence>(obj);
    if (s.size() != 2)
      throw py::value_error(std::string(name) + ": expected a mesh (.vertices, .faces) or a (vertices, faces) pair");
    vertices = s[0];
    faces = s[1];
  } else if (py::hasattr(obj, "vertices") && py::hasattr(obj, "faces")) {
    vertices = obj.attr("vertices");
    faces = obj.attr("faces");
  } else if (py::hasattr(obj, "vertices") && py::hasattr(obj, "triangles")) {  // Open3D
    vertices = obj.attr("vertices");
    faces = obj.attr("triangles");
  } else {
    throw py::value_error(std::string(name) + ": expected a mesh (.vertices, .faces) or a (vertices, faces) pair");
  }
  const std::string vname = std::string(name) + ".vertices", fname = std::string(name) + ".faces";
  MeshArrays m;
  m.positions = positions_from(vertices, vname.c_str());
  m.indices = indices_from(faces, fname.c_str(), m.positions.data.size() / 3);
  return m;
}

}  // namespace qem::python
