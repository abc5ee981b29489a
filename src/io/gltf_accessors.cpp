// Decoding and encoding glTF accessors (glTF 2.0 §3.6 "Binary data storage", §3.6.2.3
// "Sparse accessors", KHR_mesh_quantization). Every offset read from the file is checked against
// the buffer it points into, with 64-bit arithmetic, before any byte is read.
#include "io/gltf_accessors.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "qem/error.h"

namespace qem::io::gltf {

namespace {

[[noreturn]] void fail_accessor(const std::string& where, int index, const std::string& what) {
  throw Error(where + ", accessor " + std::to_string(index) + ": " + what);
}

std::size_t component_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

/// One component at `p` (little endian, as glTF stores everything).
double decode(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      auto v = static_cast<std::int8_t>(*p);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? *p / 255.0 : *p;
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return normalized ? v / 4294967295.0 : v;
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

/// The bytes [offset, offset + length) of buffer view `view`, checked; `what` names the use.
const unsigned char* view_bytes(const tinygltf::Model& model, int view, std::uint64_t offset,
                                std::uint64_t length, const std::string& where, int index, const char* what) {
  if (view < 0 || static_cast<std::size_t>(view) >= model.bufferViews.size())
    fail_accessor(where, index,
                  std::string(what) + " buffer view " + std::to_string(view) + " does not exist");
  const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(view)];
  if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= model.buffers.size())
    fail_accessor(where, index,
                  "buffer view " + std::to_string(view) + " names buffer " + std::to_string(bv.buffer) +
                      ", which does not exist");
  const tinygltf::Buffer& buffer = model.buffers[static_cast<std::size_t>(bv.buffer)];
  const std::uint64_t view_end = std::uint64_t(bv.byteOffset) + bv.byteLength;
  if (bv.byteOffset > buffer.data.size() || view_end > buffer.data.size())
    fail_accessor(where, index,
                  "buffer view " + std::to_string(view) + " (bytes " + std::to_string(bv.byteOffset) + ".." +
                      std::to_string(view_end) + ") lies outside its buffer of " +
                      std::to_string(buffer.data.size()) + " bytes");
  if (offset > bv.byteLength || length > bv.byteLength - offset)
    fail_accessor(where, index,
                  std::string(what) + " needs bytes " + std::to_string(offset) + ".." +
                      std::to_string(offset + length) + " of buffer view " + std::to_string(view) +
                      ", which has " + std::to_string(bv.byteLength));
  return buffer.data.data() + bv.byteOffset + offset;
}

}  // namespace

std::uint32_t components_of(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
    case TINYGLTF_TYPE_MAT2:
      return 4;
    case TINYGLTF_TYPE_MAT3:
      return 9;
    case TINYGLTF_TYPE_MAT4:
      return 16;
    default:
      return 0;
  }
}

int type_of(std::uint32_t n) {
  static constexpr int kTypes[] = {TINYGLTF_TYPE_SCALAR, TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3,
                                   TINYGLTF_TYPE_VEC4};
  return kTypes[std::clamp<std::uint32_t>(n, 1, 4) - 1];
}

std::vector<double> read_accessor(const tinygltf::Model& model, int index, const std::string& where,
                                  std::uint32_t* components_out) {
  if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size())
    fail_accessor(where, index,
                  "does not exist (the file has " + std::to_string(model.accessors.size()) + ")");
  const tinygltf::Accessor& a = model.accessors[static_cast<std::size_t>(index)];
  const std::uint32_t n = components_of(a.type);
  const std::size_t size = component_size(a.componentType);
  // MAT4 of 4-byte components (skins' inverse bind matrices) has no column padding, so it reads
  // as 16 tightly packed components; MAT2 / MAT3 of small types are padded per column (glTF 2.0
  // §3.6.2.4) and are not read.
  if (n == 0 || (n > 4 && !(n == 16 && size == 4)))
    fail_accessor(where, index, "type is not SCALAR, VEC2..VEC4 or a MAT4 of 4-byte components");
  if (size == 0) fail_accessor(where, index, "unknown component type " + std::to_string(a.componentType));
  if (components_out) *components_out = n;
  const std::uint64_t element = std::uint64_t(n) * size;
  std::uint64_t total_bytes = 0;
  for (const tinygltf::Buffer& b : model.buffers) total_bytes += b.data.size();
  // An accessor without a buffer view is zeros (plus its sparse values): its count is backed by no
  // data, so bound it by the document's size before allocating for it.
  if (a.count > total_bytes + (std::uint64_t(1) << 16))
    fail_accessor(where, index,
                  "count " + std::to_string(a.count) + " is larger than the file's buffers allow");

  std::vector<double> out(a.count * n, 0.0);
  if (a.bufferView >= 0 && a.count > 0) {
    if (static_cast<std::size_t>(a.bufferView) >= model.bufferViews.size())
      fail_accessor(where, index, "buffer view " + std::to_string(a.bufferView) + " does not exist");
    const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(a.bufferView)];
    std::uint64_t stride = element;
    if (bv.byteStride != 0) {
      stride = bv.byteStride;
      if (stride < element || stride % size != 0)
        fail_accessor(where, index,
                      "byte stride " + std::to_string(stride) + " does not fit its " +
                          std::to_string(element) + "-byte elements");
    }
    const std::uint64_t length = (std::uint64_t(a.count) - 1) * stride + element;
    const unsigned char* p = view_bytes(model, a.bufferView, a.byteOffset, length, where, index, "its data");
    for (std::size_t i = 0; i < a.count; ++i)
      for (std::uint32_t c = 0; c < n; ++c)
        out[i * n + c] = decode(p + i * stride + c * size, a.componentType, a.normalized);
  }
  if (a.sparse.isSparse) {
    const auto& s = a.sparse;
    if (s.count < 1 || static_cast<std::size_t>(s.count) > a.count)
      fail_accessor(where, index,
                    "sparse count " + std::to_string(s.count) + " is not in 1.." + std::to_string(a.count));
    const std::size_t isize = component_size(s.indices.componentType);
    if (isize == 0 || s.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
        s.indices.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
        s.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT)
      fail_accessor(where, index, "sparse indices must be unsigned integers");
    if (s.indices.byteOffset < 0 || s.values.byteOffset < 0)
      fail_accessor(where, index, "negative sparse byte offset");
    const unsigned char* ip = view_bytes(model, s.indices.bufferView, std::uint64_t(s.indices.byteOffset),
                                         std::uint64_t(s.count) * isize, where, index, "its sparse indices");
    const unsigned char* vp = view_bytes(model, s.values.bufferView, std::uint64_t(s.values.byteOffset),
                                         std::uint64_t(s.count) * element, where, index, "its sparse values");
    for (int k = 0; k < s.count; ++k) {
      const auto target =
          static_cast<std::uint64_t>(decode(ip + std::size_t(k) * isize, s.indices.componentType, false));
      if (target >= a.count)
        fail_accessor(
            where, index,
            "sparse index " + std::to_string(target) + " is not below the count " + std::to_string(a.count));
      for (std::uint32_t c = 0; c < n; ++c)
        out[target * n + c] = decode(vp + std::size_t(k) * element + c * size, a.componentType, a.normalized);
    }
  }
  if (a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT)
    for (std::size_t i = 0; i < out.size(); ++i)
      if (!std::isfinite(out[i]))
        fail_accessor(where, index, "element " + std::to_string(i / n) + " is not a finite number");
  return out;
}

tinygltf::Accessor append_accessor(tinygltf::Model& model, std::vector<unsigned char>& bin,
                                   const std::vector<double>& values, std::uint32_t components,
                                   int component_type, bool normalized, bool with_bounds, int target) {
  const std::size_t size = component_size(component_type);
  const std::size_t count = components ? values.size() / components : 0;
  bin.resize((bin.size() + 3) & ~std::size_t(3), 0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = bin.size();
  view.byteLength = std::max<std::size_t>(values.size() * size, 1);
  view.target = target;
  bin.resize(bin.size() + view.byteLength, 0);
  unsigned char* p = bin.data() + view.byteOffset;
  for (std::size_t i = 0; i < values.size(); ++i, p += size) {
    double v = values[i];
    if (normalized) v = std::round(std::clamp(v, 0.0, 1.0) * (size == 1 ? 255.0 : 65535.0));
    switch (component_type) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        *p = static_cast<std::uint8_t>(std::clamp(v, 0.0, 255.0));
        break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        auto u = static_cast<std::uint16_t>(std::clamp(v, 0.0, 65535.0));
        std::memcpy(p, &u, 2);
        break;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        auto u = static_cast<std::uint32_t>(std::clamp(v, 0.0, 4294967295.0));
        std::memcpy(p, &u, 4);
        break;
      }
      default: {
        auto f = static_cast<float>(v);
        std::memcpy(p, &f, 4);
        break;
      }
    }
  }
  model.bufferViews.push_back(view);

  tinygltf::Accessor a;
  a.bufferView = static_cast<int>(model.bufferViews.size() - 1);
  a.componentType = component_type;
  a.normalized = normalized;
  a.count = count;
  a.type = type_of(components);
  if (with_bounds && count > 0) {
    a.minValues.assign(components, std::numeric_limits<double>::infinity());
    a.maxValues.assign(components, -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < count; ++i)
      for (std::uint32_t c = 0; c < components; ++c) {
        // The bounds of what is stored: float-rounded, as validators compare them exactly.
        double v = static_cast<float>(values[i * components + c]);
        a.minValues[c] = std::min(a.minValues[c], v);
        a.maxValues[c] = std::max(a.maxValues[c], v);
      }
  }
  return a;
}

}  // namespace qem::io::gltf
