// A small JSON reader and writer for the viewer: the LOD manifest that `qem view` reads and the
// scene description it writes. Only what those need (RFC 8259 values, UTF-8 passed through).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace qem::view {

/// A parsed JSON value. Objects keep their keys sorted (std::map); duplicates: the last wins.
struct JsonValue {
  enum class Kind { Null, Bool, Number, String, Array, Object };
  Kind kind = Kind::Null;
  bool boolean = false;
  double number = 0;
  std::string string;
  std::vector<JsonValue> array;
  std::map<std::string, JsonValue> object;

  bool is_null() const { return kind == Kind::Null; }
  bool is_number() const { return kind == Kind::Number; }
  bool is_string() const { return kind == Kind::String; }
  bool is_array() const { return kind == Kind::Array; }
  bool is_object() const { return kind == Kind::Object; }
  /// The member `key` of an object, or nullptr (also when this is not an object).
  const JsonValue* find(const std::string& key) const;
};

/// Parses a whole JSON document. Throws qem::Error naming `name`, the line and what is wrong.
JsonValue parse_json(std::string_view text, const std::string& name);

/// `s` as a JSON string literal, quotes included.
std::string json_quote(std::string_view s);

/// A number as JSON: shortest round-trip form; NaN and infinities (not JSON) become null.
std::string json_number(double x);

}  // namespace qem::view
