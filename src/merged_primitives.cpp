#include "merged_primitives.h"

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

namespace qem {
namespace {

/// What a part without the attribute holds there: texture coordinates 0, colours white (opaque).
bool fillable(AttributeKind kind) { return kind == AttributeKind::TexCoord || kind == AttributeKind::Color; }
double fill_value(AttributeKind kind) { return kind == AttributeKind::Color ? 1.0 : 0.0; }

const VertexAttribute* find_named(const Mesh& mesh, const std::string& name) {
  for (const VertexAttribute& a : mesh.attributes)
    if (a.name == name) return &a;
  return nullptr;
}

}  // namespace

std::optional<Mesh> merge_parts(std::span<const Mesh> parts) {
  Mesh out;
  std::size_t vertices = 0;
  for (const Mesh& part : parts) {
    vertices += part.vertex_count();
    for (const VertexAttribute& a : part.attributes) {
      const VertexAttribute* seen = find_named(out, a.name);
      if (!seen)
        out.attributes.push_back({a.name, a.kind, a.components, {}});
      else if (seen->kind != a.kind || seen->components != a.components)
        return std::nullopt;
    }
  }
  if (vertices > std::numeric_limits<std::uint32_t>::max()) return std::nullopt;
  for (const VertexAttribute& a : out.attributes)
    for (const Mesh& part : parts)
      if (!fillable(a.kind) && !find_named(part, a.name)) return std::nullopt;

  out.positions.reserve(3 * vertices);
  for (VertexAttribute& a : out.attributes) a.values.reserve(a.components * vertices);
  for (std::uint32_t k = 0; k < parts.size(); ++k) {
    const Mesh& part = parts[k];
    const auto base = static_cast<std::uint32_t>(out.vertex_count());
    out.positions.insert(out.positions.end(), part.positions.begin(), part.positions.end());
    for (std::uint32_t v : part.indices) out.indices.push_back(base + v);
    out.face_materials.insert(out.face_materials.end(), part.face_count(), k);
    for (VertexAttribute& a : out.attributes) {
      if (const VertexAttribute* own = find_named(part, a.name))
        a.values.insert(a.values.end(), own->values.begin(), own->values.end());
      else
        a.values.insert(a.values.end(), a.components * part.vertex_count(), fill_value(a.kind));
    }
  }
  return out;
}

Mesh split_part(const Mesh& merged, std::uint32_t part, const Mesh& like) {
  Mesh out;
  std::vector<const VertexAttribute*> from;
  for (const VertexAttribute& a : like.attributes) {
    out.attributes.push_back({a.name, a.kind, a.components, {}});
    from.push_back(find_named(merged, a.name));
  }
  std::vector<std::uint32_t> renumbered(merged.vertex_count(), std::numeric_limits<std::uint32_t>::max());
  for (std::size_t f = 0; f < merged.face_count(); ++f) {
    const std::uint32_t material = merged.face_materials.empty() ? 0 : merged.face_materials[f];
    if (material != part) continue;
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t v = merged.indices[3 * f + c];
      if (renumbered[v] == std::numeric_limits<std::uint32_t>::max()) {
        renumbered[v] = static_cast<std::uint32_t>(out.vertex_count());
        out.positions.insert(out.positions.end(), &merged.positions[3 * std::size_t(v)],
                             &merged.positions[3 * std::size_t(v)] + 3);
        for (std::size_t i = 0; i < from.size(); ++i) {
          VertexAttribute& a = out.attributes[i];
          if (from[i])
            a.values.insert(a.values.end(), &from[i]->values[a.components * std::size_t(v)],
                            &from[i]->values[a.components * std::size_t(v)] + a.components);
          else  // (merge_parts carries every attribute; a caller's merged mesh might not)
            a.values.insert(a.values.end(), a.components, fill_value(a.kind));
        }
      }
      out.indices.push_back(renumbered[v]);
    }
  }
  return out;
}

}  // namespace qem
