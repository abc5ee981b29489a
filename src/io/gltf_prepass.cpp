#include "io/gltf_prepass.h"

#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>

#include "io/gltf_draco.h"
#include "io/gltf_meshopt.h"

namespace qem::io::gltf {

namespace {

std::uint32_t read_u32(std::string_view bytes, std::size_t at) {
  std::uint32_t v;
  std::memcpy(&v, bytes.data() + at, 4);
  return v;
}

void append_u32(std::string& out, std::uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);
  out.append(b, 4);
}

}  // namespace

bool is_glb(std::string_view bytes) { return bytes.size() >= 4 && bytes.substr(0, 4) == "glTF"; }

bool names_compression(std::string_view json) {
  return json.find("KHR_draco_mesh_compression") != std::string_view::npos ||
         json.find("EXT_meshopt_compression") != std::string_view::npos;
}

std::optional<std::string_view> json_of(std::string_view bytes) {
  if (!is_glb(bytes)) return bytes;
  // The header (magic, version, length), then the first chunk: length, type "JSON", data.
  if (bytes.size() < 20 || bytes.substr(16, 4) != "JSON" || read_u32(bytes, 12) > bytes.size() - 20)
    return std::nullopt;
  return bytes.substr(20, read_u32(bytes, 12));
}

std::string prepare_for_tinygltf(std::string_view bytes) {
  const bool glb = is_glb(bytes);
  const std::optional<std::string_view> json_text = json_of(bytes);
  if (!json_text) return "";  // for tinygltf to refuse with its own message
  const std::string_view text = *json_text;
  if (!names_compression(text)) return "";
  nlohmann::json doc = nlohmann::json::parse(text, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) return "";
  const bool draco = set_draco_indices_aside(doc);
  const bool meshopt = set_fallback_buffers_aside(doc);
  if (!draco && !meshopt) return "";
  std::string json = doc.dump();
  if (!glb) return json;
  json.resize((json.size() + 3) & ~std::size_t(3),
              ' ');  // chunks are 4-byte aligned, JSON padded with spaces
  const std::string_view rest = bytes.substr(20 + text.size());
  std::string out = "glTF";
  append_u32(out, read_u32(bytes, 4));
  append_u32(out, static_cast<std::uint32_t>(12 + 8 + json.size() + rest.size()));
  append_u32(out, static_cast<std::uint32_t>(json.size()));
  out += "JSON";
  out += json;
  out += rest;
  return out;
}

}  // namespace qem::io::gltf
