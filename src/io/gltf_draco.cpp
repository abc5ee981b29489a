#include "io/gltf_draco.h"

#include <draco/attributes/attribute_quantization_transform.h>
#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>
#include <draco/core/quantization_utils.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "io/gltf_accessors.h"
#include "qem/error.h"

namespace qem::io::gltf {

namespace {

constexpr const char* kDraco = "KHR_draco_mesh_compression";
constexpr const char* kIndicesAside = "qem_indices";  // set_draco_indices_aside's key

// Every point's value of `attribute` converted to T (draco checks that each fits), appended to
// `bytes`; false when one does not fit.
template <class T>
bool append_values(const draco::PointCloud& mesh, const draco::PointAttribute& attribute,
                   std::vector<unsigned char>& bytes) {
  const int n = attribute.num_components();
  T values[4] = {};
  for (draco::PointIndex i(0); i < mesh.num_points(); ++i) {
    if (!attribute.ConvertValue<T>(attribute.mapped_index(i), static_cast<std::int8_t>(n), values))
      return false;
    const auto* p = reinterpret_cast<const unsigned char*>(values);
    bytes.insert(bytes.end(), p, p + sizeof(T) * static_cast<std::size_t>(n));
  }
  return true;
}

// A position attribute decoded without its quantization transform (the decoder's
// skip_attribute_transform): its integers dequantized as libdraco's own inverse transform does
// (AttributeQuantizationTransform: the integer times range / (2^bits - 1), plus the minimum, in
// float), appended to `bytes` as floats; the grid's spacing in `step`. False when its quantization
// cannot be read.
bool append_dequantized(const draco::PointCloud& mesh, const draco::PointAttribute& attribute,
                        std::vector<unsigned char>& bytes, double& step) {
  draco::AttributeQuantizationTransform transform;
  if (!attribute.GetAttributeTransformData() || !transform.InitFromAttribute(attribute)) return false;
  const int n = attribute.num_components();
  const int bits = transform.quantization_bits();
  if (bits < 1 || bits > 30) return false;  // (libdraco's own bound)
  const int32_t max_quantized = (int32_t(1) << bits) - 1;
  draco::Dequantizer dequantizer;
  if (n > 4 || !dequantizer.Init(transform.range(), max_quantized)) return false;
  step = double(transform.range()) / max_quantized;
  std::int32_t q[4] = {};
  for (draco::PointIndex i(0); i < mesh.num_points(); ++i) {
    if (!attribute.ConvertValue<std::int32_t>(attribute.mapped_index(i), static_cast<std::int8_t>(n), q))
      return false;
    for (int c = 0; c < n; ++c) {
      const float value = dequantizer.DequantizeFloat(q[c]) + transform.min_value(c);
      const auto* b = reinterpret_cast<const unsigned char*>(&value);
      bytes.insert(bytes.end(), b, b + sizeof(float));
    }
  }
  return true;
}

bool append_values(int component_type, const draco::PointCloud& mesh, const draco::PointAttribute& attribute,
                   std::vector<unsigned char>& bytes) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return append_values<std::int8_t>(mesh, attribute, bytes);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return append_values<std::uint8_t>(mesh, attribute, bytes);
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return append_values<std::int16_t>(mesh, attribute, bytes);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return append_values<std::uint16_t>(mesh, attribute, bytes);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return append_values<std::uint32_t>(mesh, attribute, bytes);
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return append_values<float>(mesh, attribute, bytes);
    default:
      return false;
  }
}

// The faces' corners (of a point cloud, the points in order) in the index accessor's component
// type; false when an index does not fit it.
bool append_indices(int component_type, const draco::PointCloud& cloud, const draco::Mesh* mesh,
                    std::vector<unsigned char>& bytes) {
  const std::size_t size = component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? 1
                           : component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 2
                           : component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT   ? 4
                                                                                      : 0;
  if (size == 0) return false;
  const std::uint64_t limit = size == 4 ? UINT32_MAX : (std::uint64_t(1) << (8 * size)) - 1;
  const std::size_t count = mesh ? 3 * std::size_t(mesh->num_faces()) : cloud.num_points();
  for (std::size_t c = 0; c < count; ++c) {
    const std::uint32_t index =
        mesh ? mesh->face(draco::FaceIndex(std::uint32_t(c / 3)))[c % 3].value() : std::uint32_t(c);
    if (index >= cloud.num_points() || index > limit) return false;
    unsigned char b[4];
    std::memcpy(b, &index, 4);  // little endian, as glTF is
    bytes.insert(bytes.end(), b, b + size);
  }
  return true;
}

// `bytes` as a new buffer and buffer view; accessor `a` reads it from its start.
void attach(tinygltf::Model& model, tinygltf::Accessor& a, std::vector<unsigned char>&& bytes,
            std::size_t count, int target) {
  tinygltf::BufferView view;
  view.buffer = static_cast<int>(model.buffers.size());
  view.byteLength = bytes.size();
  view.target = target;
  tinygltf::Buffer buffer;
  buffer.data = std::move(bytes);
  model.buffers.push_back(std::move(buffer));
  model.bufferViews.push_back(std::move(view));
  a.bufferView = static_cast<int>(model.bufferViews.size() - 1);
  a.byteOffset = 0;
  a.count = count;
  a.sparse.isSparse = false;
}

void decode_primitive(tinygltf::Model& model, tinygltf::Primitive& p, const std::string& where,
                      std::set<std::size_t>& compressed_views, double& position_step) {
  const tinygltf::Value& ext = p.extensions.at(kDraco);
  const tinygltf::Value& view_value = ext.Get("bufferView");
  const tinygltf::Value& names = ext.Get("attributes");
  if (!view_value.IsInt() || !names.IsObject())
    throw Error(where + ": " + kDraco + " needs an integer bufferView and an attributes object");
  const int v = view_value.GetNumberAsInt();
  if (v < 0 || static_cast<std::size_t>(v) >= model.bufferViews.size())
    throw Error(where + ": " + kDraco + " names buffer view " + std::to_string(v) + ", which does not exist");
  const tinygltf::BufferView& view = model.bufferViews[static_cast<std::size_t>(v)];
  const std::vector<unsigned char>& data = model.buffers[static_cast<std::size_t>(view.buffer)].data;

  draco::DecoderBuffer stream;
  // A POINTS primitive is a point cloud; any other is decoded as faces, a triangle list (so a strip
  // becomes TRIANGLES).
  const bool points = p.mode == TINYGLTF_MODE_POINTS;
  std::unique_ptr<draco::PointCloud> cloud;
  const auto take = [&](auto&& decoded) {
    if (!decoded.ok())
      throw Error(where + ": the Draco data in buffer view " + std::to_string(v) +
                  " cannot be decoded: " + decoded.status().error_msg_string());
    cloud = std::move(decoded).value();
  };
  // A mesh's positions are read as the encoder's integers with its quantization, and dequantized
  // here as libdraco would: the grid's spacing tells the primitives of one mesh, each quantized in
  // its own box, where they meet (GltfPrimitiveInfo::position_step). A point cloud is decoded as is.
  const auto decode = [&](bool keep_positions_quantized) {
    draco::Decoder decoder;
    if (keep_positions_quantized) decoder.SetSkipAttributeTransform(draco::GeometryAttribute::POSITION);
    stream.Init(reinterpret_cast<const char*>(data.data() + view.byteOffset), view.byteLength);
    if (points)
      take(decoder.DecodePointCloudFromBuffer(&stream));
    else
      take(decoder.DecodeMeshFromBuffer(&stream));
  };
  decode(!points);
  // (An integer accessor for a position Draco quantized, unusual, takes libdraco's own conversion.)
  const auto quantized = [](const draco::PointAttribute* a) {
    return a && a->attribute_type() == draco::GeometryAttribute::POSITION && a->GetAttributeTransformData();
  };
  for (const std::string& semantic : names.Keys()) {
    const tinygltf::Value& id = names.Get(semantic);
    const auto named = p.attributes.find(semantic);
    if (!id.IsInt() || id.GetNumberAsInt() < 0 || named == p.attributes.end() || named->second < 0 ||
        static_cast<std::size_t>(named->second) >= model.accessors.size())
      continue;  // (refused below)
    if (quantized(cloud->GetAttributeByUniqueId(static_cast<std::uint32_t>(id.GetNumberAsInt()))) &&
        model.accessors[static_cast<std::size_t>(named->second)].componentType !=
            TINYGLTF_COMPONENT_TYPE_FLOAT) {
      decode(false);
      break;
    }
  }
  const draco::PointCloud& mesh = *cloud;
  const draco::Mesh* faces = points ? nullptr : static_cast<const draco::Mesh*>(&mesh);
  if ((faces && faces->num_faces() == 0) || mesh.num_points() == 0)
    throw Error(where + ": the Draco data in buffer view " + std::to_string(v) + " holds no " +
                (points ? "points" : "triangles"));
  compressed_views.insert(static_cast<std::size_t>(v));

  auto accessor_of = [&](int index, const std::string& what) -> tinygltf::Accessor& {
    if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size())
      throw Error(where + " (" + what + "): accessor " + std::to_string(index) + " does not exist");
    return model.accessors[static_cast<std::size_t>(index)];
  };
  for (const std::string& semantic : names.Keys()) {
    const tinygltf::Value& id = names.Get(semantic);
    const auto named = p.attributes.find(semantic);
    if (!id.IsInt() || named == p.attributes.end())
      throw Error(where + ": " + kDraco + " names " + semantic +
                  (id.IsInt() ? ", which the primitive does not have" : " without an integer id"));
    tinygltf::Accessor& a = accessor_of(named->second, semantic);
    const draco::PointAttribute* attribute =
        id.GetNumberAsInt() < 0
            ? nullptr
            : mesh.GetAttributeByUniqueId(static_cast<std::uint32_t>(id.GetNumberAsInt()));
    if (!attribute)
      throw Error(where + " (" + semantic + "): the Draco data has no attribute " +
                  std::to_string(id.GetNumberAsInt()));
    if (attribute->num_components() != components_of(a.type) || attribute->num_components() > 4)
      throw Error(where + " (" + semantic + "), accessor " + std::to_string(named->second) +
                  ": the Draco attribute has " + std::to_string(attribute->num_components()) +
                  " components, the accessor's type " + std::to_string(components_of(a.type)));
    // glTF has no boolean component type, and libdraco reads a boolean value's byte as a bool
    // (undefined behaviour for any byte but 0 and 1): such an attribute is refused, not read.
    if (attribute->data_type() == draco::DT_BOOL || attribute->data_type() == draco::DT_INVALID)
      throw Error(where + " (" + semantic + "): the Draco attribute " +
                  (attribute->data_type() == draco::DT_BOOL ? "holds booleans" : "has no data type") +
                  ", which no glTF accessor can hold");
    std::vector<unsigned char> bytes;
    double step = 0;
    if (quantized(attribute)) {
      if (!append_dequantized(mesh, *attribute, bytes, step))
        throw Error(where + " (" + semantic + "): the Draco attribute's quantization cannot be read");
      if (semantic == "POSITION") position_step = step;
    } else if (!append_values(a.componentType, mesh, *attribute, bytes))
      throw Error(where + " (" + semantic + "), accessor " + std::to_string(named->second) +
                  ": a decoded value does not fit the accessor's component type " +
                  std::to_string(a.componentType));
    attach(model, a, std::move(bytes), mesh.num_points(), TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  if (ext.Has(kIndicesAside) && ext.Get(kIndicesAside).IsInt())
    p.indices = ext.Get(kIndicesAside).GetNumberAsInt();
  // Draco stores faces: a primitive of faces without indices gets an index accessor of its own.
  if (p.indices < 0 && faces) {
    tinygltf::Accessor indices;
    indices.type = TINYGLTF_TYPE_SCALAR;
    indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    model.accessors.push_back(std::move(indices));
    p.indices = static_cast<int>(model.accessors.size() - 1);
  }
  if (p.indices >= 0) {
    tinygltf::Accessor& ia = accessor_of(p.indices, "indices");
    std::vector<unsigned char> bytes;
    if (!append_indices(ia.componentType, mesh, faces, bytes))
      throw Error(where + " (indices), accessor " + std::to_string(p.indices) + ": component type " +
                  std::to_string(ia.componentType) + " cannot hold the decoded indices");
    attach(model, ia, std::move(bytes), faces ? 3 * std::size_t(faces->num_faces()) : mesh.num_points(),
           TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  }
  if (faces) p.mode = TINYGLTF_MODE_TRIANGLES;
  p.extensions.erase(kDraco);
}

}  // namespace

bool set_draco_indices_aside(nlohmann::json& doc) {
  if (!doc.contains("meshes") || !doc["meshes"].is_array()) return false;
  const nlohmann::json* accessors =
      doc.contains("accessors") && doc["accessors"].is_array() ? &doc["accessors"] : nullptr;
  bool moved = false;
  for (nlohmann::json& mesh : doc["meshes"]) {
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    for (nlohmann::json& p : mesh["primitives"]) {
      if (!p.is_object() || !p.contains("extensions") || !p["extensions"].is_object() ||
          !p["extensions"].contains(kDraco) || !p["extensions"][kDraco].is_object() ||
          !p.contains("indices") || !p["indices"].is_number_unsigned())
        continue;
      const std::size_t a = p["indices"].get<std::size_t>();
      if (!accessors || a >= accessors->size() || !(*accessors)[a].is_object() ||
          (*accessors)[a].contains("bufferView"))
        continue;
      p["extensions"][kDraco][kIndicesAside] = p["indices"];
      p.erase("indices");
      moved = true;
    }
  }
  return moved;
}

void decode_draco(tinygltf::Model& model, const std::string& name, std::set<std::size_t>& compressed_views,
                  PositionSteps& position_steps) {
  for (std::size_t m = 0; m < model.meshes.size(); ++m)
    for (std::size_t k = 0; k < model.meshes[m].primitives.size(); ++k) {
      tinygltf::Primitive& p = model.meshes[m].primitives[k];
      if (!p.extensions.count(kDraco)) continue;
      double step = 0;
      decode_primitive(model, p, name + ": mesh " + std::to_string(m) + ", primitive " + std::to_string(k),
                       compressed_views, step);
      if (step > 0) position_steps[{m, k}] = step;
    }
  // No primitive is compressed now (a list naming an extension nothing uses is dropped too).
  for (std::vector<std::string>* list : {&model.extensionsUsed, &model.extensionsRequired})
    list->erase(std::remove(list->begin(), list->end(), kDraco), list->end());
}

}  // namespace qem::io::gltf
