#include "io/gltf_meshopt.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "qem/error.h"

namespace qem::io::gltf {

namespace {

constexpr const char* kMeshopt = "EXT_meshopt_compression";
constexpr const char* kLengthAside = "qem_byteLength";  // set_fallback_buffers_aside's key
// The largest number a length or count of the extension may hold (a .glb is below 4 GiB).
constexpr std::uint64_t kLargestBuffer = std::uint64_t(1) << 32;

std::uint64_t unsigned_field(const tinygltf::Value& ext, const char* key, const std::string& where,
                             bool required, std::uint64_t otherwise = 0) {
  if (!ext.Has(key)) {
    if (required) throw Error(where + ": " + kMeshopt + " has no " + key);
    return otherwise;
  }
  const tinygltf::Value& v = ext.Get(key);
  if (!v.IsNumber() || v.GetNumberAsDouble() < 0 || v.GetNumberAsDouble() > double(kLargestBuffer) ||
      v.GetNumberAsDouble() != static_cast<double>(static_cast<std::uint64_t>(v.GetNumberAsDouble())))
    throw Error(where + ": " + kMeshopt + "'s " + key + " is not a whole number in range");
  return static_cast<std::uint64_t>(v.GetNumberAsDouble());
}

std::string string_field(const tinygltf::Value& ext, const char* key, const char* otherwise) {
  return ext.Has(key) && ext.Get(key).IsString() ? ext.Get(key).Get<std::string>() : otherwise;
}

void decode_view(tinygltf::Model& model, std::size_t v, const std::string& name) {
  tinygltf::BufferView& view = model.bufferViews[v];
  const std::string where = name + ": buffer view " + std::to_string(v);
  const tinygltf::Value& ext = view.extensions.at(kMeshopt);
  const std::uint64_t source = unsigned_field(ext, "buffer", where, true);
  const std::uint64_t offset = unsigned_field(ext, "byteOffset", where, false);
  const std::uint64_t length = unsigned_field(ext, "byteLength", where, true);
  const std::uint64_t stride = unsigned_field(ext, "byteStride", where, true);
  const std::uint64_t count = unsigned_field(ext, "count", where, true);
  const std::string mode = string_field(ext, "mode", ""), filter = string_field(ext, "filter", "NONE");
  // The data's place in its buffer was checked by decode_meshopt.
  const std::vector<unsigned char>& in = model.buffers[source].data;
  if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size())
    throw Error(where + " names buffer " + std::to_string(view.buffer) + ", which does not exist");
  std::vector<unsigned char>& out = model.buffers[static_cast<std::size_t>(view.buffer)].data;
  if (count * stride != view.byteLength || view.byteOffset > out.size() ||
      view.byteLength > out.size() - view.byteOffset)
    throw Error(where + ": " + std::to_string(count) + " elements of " + std::to_string(stride) +
                " bytes do not fill the view (" + std::to_string(view.byteLength) + " bytes at " +
                std::to_string(view.byteOffset) + " in a buffer of " + std::to_string(out.size()) + ")");
  // The decoders assume these (they assert them); a file gets an error instead.
  const bool index_stride = stride == 2 || stride == 4;
  if (mode == "ATTRIBUTES"  ? stride == 0 || stride > 256 || stride % 4 != 0
      : mode == "TRIANGLES" ? !index_stride || count % 3 != 0
      : mode == "INDICES"   ? !index_stride
                            : true)
    throw Error(where + ": " + kMeshopt + " mode \"" + mode + "\" with byteStride " + std::to_string(stride) +
                " and count " + std::to_string(count) + " is not allowed");
  if (filter != "NONE" && (mode != "ATTRIBUTES" || (filter == "OCTAHEDRAL" && stride != 4 && stride != 8) ||
                           (filter == "QUATERNION" && stride != 8) ||
                           (filter != "OCTAHEDRAL" && filter != "QUATERNION" && filter != "EXPONENTIAL")))
    throw Error(where + ": " + kMeshopt + " filter \"" + filter + "\" is unknown or does not fit mode \"" +
                mode + "\" and byteStride " + std::to_string(stride));
  unsigned char* target = out.data() + view.byteOffset;
  const unsigned char* data = in.data() + offset;
  const int status = mode == "ATTRIBUTES"  ? meshopt_decodeVertexBuffer(target, count, stride, data, length)
                     : mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(target, count, stride, data, length)
                                           : meshopt_decodeIndexSequence(target, count, stride, data, length);
  if (status != 0)
    throw Error(where + ": " + kMeshopt + " data does not decode (meshoptimizer's status " +
                std::to_string(status) + ")");
  if (filter == "OCTAHEDRAL") meshopt_decodeFilterOct(target, count, stride);
  if (filter == "QUATERNION") meshopt_decodeFilterQuat(target, count, stride);
  if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(target, count, stride);
  view.extensions.erase(kMeshopt);
}

}  // namespace

bool set_fallback_buffers_aside(nlohmann::json& doc) {
  if (!doc.contains("buffers") || !doc["buffers"].is_array()) return false;
  bool changed = false;
  for (nlohmann::json& b : doc["buffers"]) {
    if (!b.is_object() || b.contains("uri") || !b.contains("extensions") || !b["extensions"].is_object() ||
        !b["extensions"].contains(kMeshopt) || !b["extensions"][kMeshopt].is_object() ||
        b["extensions"][kMeshopt].value("fallback", false) != true || !b.contains("byteLength"))
      continue;
    b["extensions"][kMeshopt][kLengthAside] = b["byteLength"];
    b["byteLength"] = 1;
    b["uri"] = "data:application/octet-stream;base64,AA==";  // one zero byte
    changed = true;
  }
  return changed;
}

void decode_meshopt(tinygltf::Model& model, const std::string& name) {
  // A fallback buffer holds no data: qem lays its compressed views out one after the other in a
  // buffer of their own length (their offsets change; the writer re-packs every view anyway). A
  // view may not claim more than its data can expand to: the vertex codec's most is 64 bytes per
  // compressed byte (a 2-bit header per 16 bytes of one channel; the index codecs' is 12), and that
  // data must lie in its buffer, so a file cannot make qem allocate far beyond its own size.
  std::vector<char> fallback(model.buffers.size(), 0);
  for (std::size_t b = 0; b < model.buffers.size(); ++b)
    fallback[b] = model.buffers[b].extensions.count(kMeshopt) &&
                  model.buffers[b].extensions.at(kMeshopt).Has(kLengthAside);
  std::vector<std::uint64_t> laid(model.buffers.size(), 0);
  for (std::size_t v = 0; v < model.bufferViews.size(); ++v) {
    tinygltf::BufferView& view = model.bufferViews[v];
    if (!view.extensions.count(kMeshopt)) continue;
    const std::string where = name + ": buffer view " + std::to_string(v);
    const tinygltf::Value& ext = view.extensions.at(kMeshopt);
    const std::uint64_t source = unsigned_field(ext, "buffer", where, true);
    const std::uint64_t offset = unsigned_field(ext, "byteOffset", where, false);
    const std::uint64_t length = unsigned_field(ext, "byteLength", where, true);
    if (source >= model.buffers.size() || fallback[source] || offset > model.buffers[source].data.size() ||
        length > model.buffers[source].data.size() - offset)
      throw Error(where + ": " + kMeshopt + "'s data (buffer " + std::to_string(source) + ", bytes " +
                  std::to_string(offset) + ", " + std::to_string(length) + " long) is not in the file");
    if (view.byteLength > 64 * length + 256)
      throw Error(where + ": " + std::to_string(length) + " bytes of " + kMeshopt +
                  " data cannot decode to " + std::to_string(view.byteLength));
    if (view.buffer >= 0 && static_cast<std::size_t>(view.buffer) < fallback.size() &&
        fallback[static_cast<std::size_t>(view.buffer)]) {
      std::uint64_t& end = laid[static_cast<std::size_t>(view.buffer)];
      view.byteOffset = end;
      end = (end + view.byteLength + 3) & ~std::uint64_t(3);  // 4-byte aligned, as glTF asks
    }
  }
  for (std::size_t b = 0; b < model.buffers.size(); ++b) {
    tinygltf::Buffer& buffer = model.buffers[b];
    if (!buffer.extensions.count(kMeshopt)) continue;
    if (fallback[b]) {
      buffer.data.assign(laid[b], 0);
      buffer.uri.clear();
    }
    buffer.extensions.erase(kMeshopt);
  }
  for (std::size_t v = 0; v < model.bufferViews.size(); ++v)
    if (model.bufferViews[v].extensions.count(kMeshopt)) decode_view(model, v, name);
  for (std::vector<std::string>* list : {&model.extensionsUsed, &model.extensionsRequired})
    list->erase(std::remove(list->begin(), list->end(), kMeshopt), list->end());
}

}  // namespace qem::io::gltf
