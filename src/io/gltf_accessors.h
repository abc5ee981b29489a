// glTF accessors as flat arrays of doubles, both ways: decoding any accessor (strided, normalised
// or quantized integers, sparse) with every range checked, and appending new float / integer
// accessors to a byte buffer. Works on tinygltf's Model (declarations only: the implementation of
// tiny_gltf.h is compiled once, in gltf.cpp).
#pragma once

#include <tiny_gltf.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace qem::io::gltf {

/// Components per element of a glTF accessor type (SCALAR 1 ... VEC4 4, MAT4 16), 0 if unknown.
std::uint32_t components_of(int type);
/// The glTF accessor type with `n` components (1..4).
int type_of(std::uint32_t n);

/// Reads accessor `index` (SCALAR, VEC2..VEC4, or MAT4 of floats) as count x components values. Normalised integers are mapped to
/// [0, 1] or [-1, 1] as the spec says; other integers keep their value. Throws qem::Error
/// "<where>, accessor <index>: <what>" when the accessor or its data is out of range, or a float
/// is not finite.
std::vector<double> read_accessor(const tinygltf::Model& model, int index, const std::string& where,
                                  std::uint32_t* components = nullptr);

/// Appends data to `bin` (4-byte aligned) as a new buffer view on buffer 0 and a new accessor, and
/// returns the accessor (not added to the model: the caller places it). `component_type` is a
/// TINYGLTF_COMPONENT_TYPE_*; `with_bounds` fills min/max (required for POSITION). `target` is the
/// buffer view target (ARRAY_BUFFER / ELEMENT_ARRAY_BUFFER).
tinygltf::Accessor append_accessor(tinygltf::Model& model, std::vector<unsigned char>& bin,
                                   const std::vector<double>& values, std::uint32_t components,
                                   int component_type, bool normalized, bool with_bounds, int target);

}  // namespace qem::io::gltf
