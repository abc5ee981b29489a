// PLY's scalar types (Turk 1994's names and the sized aliases), shared by the in-memory reader
// (src/io/ply.cpp) and the streaming one (src/outofcore/mesh_stream.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace qem::io::ply {

enum class Type : std::uint8_t { I8, U8, I16, U16, I32, U32, F32, F64 };

/// Sets `t` from a PLY type name; false when the name is unknown.
inline bool parse_type(std::string_view s, Type& t) {
  static constexpr struct {
    std::string_view name;
    Type type;
  } kTypes[] = {{"char", Type::I8},   {"int8", Type::I8},     {"uchar", Type::U8},   {"uint8", Type::U8},
                {"short", Type::I16}, {"int16", Type::I16},   {"ushort", Type::U16}, {"uint16", Type::U16},
                {"int", Type::I32},   {"int32", Type::I32},   {"uint", Type::U32},   {"uint32", Type::U32},
                {"float", Type::F32}, {"float32", Type::F32}, {"double", Type::F64}, {"float64", Type::F64}};
  for (const auto& k : kTypes)
    if (k.name == s) {
      t = k.type;
      return true;
    }
  return false;
}

/// Bytes of one value in a binary body.
constexpr std::size_t type_size(Type t) {
  switch (t) {
    case Type::I8:
    case Type::U8:
      return 1;
    case Type::I16:
    case Type::U16:
      return 2;
    case Type::I32:
    case Type::U32:
    case Type::F32:
      return 4;
    case Type::F64:
      return 8;
  }
  return 0;
}

constexpr bool is_integral(Type t) { return t != Type::F32 && t != Type::F64; }

}  // namespace qem::io::ply
