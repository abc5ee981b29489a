// The public entry points of qem/io.h: format detection (extension, then content), dispatch to the
// per-format readers and writers, welding policy, and atomic saving.
#include <algorithm>
#include <cctype>
#include <new>
#include <string>

#include "io/io_common.h"
#include "qem/gltf.h"
#include "qem/io.h"

namespace qem {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string extension_of(const std::string& path) {
  std::size_t slash = path.find_last_of('/');
  std::size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return lower(path.substr(dot + 1));
}

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

/// The first word of the first line that is not blank or a '#' comment.
std::string_view first_word(std::string_view bytes) {
  std::size_t i = 0;
  for (;;) {
    while (i < bytes.size() && is_blank(bytes[i])) ++i;
    if (i < bytes.size() && bytes[i] == '#') {
      while (i < bytes.size() && bytes[i] != '\n') ++i;
      continue;
    }
    break;
  }
  std::size_t j = i;
  while (j < bytes.size() && !is_blank(bytes[j]) && j - i < 64) ++j;
  return bytes.substr(i, j - i);
}

/// Recognises a format by its content, or returns Auto.
FileFormat sniff(std::string_view bytes) {
  if (bytes.substr(0, 4) == "glTF") return FileFormat::Gltf;
  if (bytes.size() >= 4 && bytes.substr(0, 3) == "ply" && (bytes[3] == '\n' || bytes[3] == '\r'))
    return FileFormat::Ply;
  if (io::stl_is_binary(bytes)) return FileFormat::Stl;
  std::string_view w = first_word(bytes);
  if (w.size() >= 3 && w.size() <= 7 && w.substr(w.size() - 3) == "OFF") return FileFormat::Off;
  if (w == "solid") return FileFormat::Stl;
  static constexpr std::string_view kObj[] = {"v", "vt", "vn",     "vp",     "f", "o",
                                              "g", "s",  "usemtl", "mtllib", "l", "p"};
  if (std::find(std::begin(kObj), std::end(kObj), w) != std::end(kObj)) return FileFormat::Obj;
  // A glTF JSON document opens with '{' (no other format here does).
  if (!w.empty() && w[0] == '{') return FileFormat::Gltf;
  return FileFormat::Auto;
}

Mesh gltf_scene(const GltfDocument& doc, std::string_view bytes, LoadReport& report) {
  report.format = FileFormat::Gltf;
  report.binary = bytes.substr(0, 4) == "glTF";
  report.warnings = doc.notes();
  return doc.scene_mesh();
}

Mesh dispatch(std::string_view bytes, FileFormat format, const std::string& name, const LoadOptions& options,
              LoadReport& report) {
  if (bytes.empty()) io::fail(name, "empty file");
  if (format == FileFormat::Auto) {
    format = sniff(bytes);
    if (format == FileFormat::Auto)
      io::fail(name, "unknown mesh format (content is not OBJ, PLY, STL, OFF or glTF)");
  }
  try {
    switch (format) {
      case FileFormat::Obj:
        return io::parse_obj(bytes, name, options, report);
      case FileFormat::Ply:
        return io::parse_ply(bytes, name, options, report);
      case FileFormat::Stl:
        return io::parse_stl(bytes, name, options, report);
      case FileFormat::Off:
        return io::parse_off(bytes, name, options, report);
      case FileFormat::Gltf:
        // From memory: buffers must be embedded (no file beside `name` is read).
        return gltf_scene(GltfDocument::parse(bytes, name), bytes, report);
      case FileFormat::Auto:
        break;
    }
  } catch (const std::bad_alloc&) {
    io::fail(name, "out of memory while reading");
  } catch (const std::length_error&) {
    io::fail(name, "out of memory while reading");
  }
  io::fail(name, "unknown mesh format");
}

}  // namespace

FileFormat format_from_extension(const std::string& path) {
  std::string e = extension_of(path);
  if (e == "obj") return FileFormat::Obj;
  if (e == "ply") return FileFormat::Ply;
  if (e == "stl") return FileFormat::Stl;
  if (e == "off") return FileFormat::Off;
  if (e == "gltf" || e == "glb") return FileFormat::Gltf;
  return FileFormat::Auto;
}

Mesh parse_mesh(std::string_view bytes, FileFormat format, const std::string& name,
                const LoadOptions& options, LoadReport* report) {
  LoadReport local;
  LoadReport& r = report ? *report : local;
  r = LoadReport{};
  Mesh mesh = dispatch(bytes, format, name, options, r);
  // The STL reader welds while it reads (it never builds the unwelded soup unless Weld::Off).
  if (options.weld == Weld::On && r.format != FileFormat::Stl) r.vertices_welded = weld_exact(mesh);
  return mesh;
}

Mesh load_mesh(const std::string& path, const LoadOptions& options, LoadReport* report) {
  io::FileData file(path);
  std::string_view bytes = file.bytes();
  FileFormat format = options.format != FileFormat::Auto ? options.format : format_from_extension(path);
  if (format == FileFormat::Auto && sniff(bytes) == FileFormat::Auto) {
    std::string ext = extension_of(path);
    io::fail(path, "unknown mesh format (" +
                       (ext.empty() ? std::string("no extension") : "extension '." + ext + "'") +
                       ", and the content is not OBJ, PLY, STL, OFF or glTF)");
  }
  if (format == FileFormat::Gltf || (format == FileFormat::Auto && sniff(bytes) == FileFormat::Gltf)) {
    // From a file: a .gltf's buffers may be files beside it.
    LoadReport local;
    LoadReport& r = report ? *report : local;
    r = LoadReport{};
    Mesh mesh;
    try {
      mesh = gltf_scene(GltfDocument::load(path), bytes, r);
    } catch (const std::bad_alloc&) {
      io::fail(path, "out of memory while reading");
    }
    if (options.weld == Weld::On) r.vertices_welded = weld_exact(mesh);
    return mesh;
  }
  return parse_mesh(bytes, format, path, options, report);
}

std::string serialize_mesh(const Mesh& mesh, const SaveOptions& options) {
  io::check_mesh_for_writing(mesh);
  switch (options.format) {
    case FileFormat::Obj:
      return io::write_obj(mesh);
    case FileFormat::Ply:
      return io::write_ply(mesh, options.binary, options.double_precision);
    case FileFormat::Stl:
      return io::write_stl(mesh, options.binary);
    case FileFormat::Off:
      return io::write_off(mesh);
    case FileFormat::Gltf:
      return serialize_gltf(mesh, options.binary);
    case FileFormat::Auto:
      break;
  }
  throw Error("cannot serialise a mesh without a format");
}

std::string serialize_mesh(const Mesh& mesh, FileFormat format, bool binary) {
  SaveOptions o;
  o.format = format;
  o.binary = binary;
  return serialize_mesh(mesh, o);
}

void save_mesh(const std::string& path, const Mesh& mesh, const SaveOptions& options) {
  SaveOptions o = options;
  if (o.format == FileFormat::Auto) o.format = format_from_extension(path);
  if (o.format == FileFormat::Auto)
    throw Error(
        path +
        ": cannot tell the output format from the extension (use .obj, .ply, .stl, .off, .glb or .gltf)");
  if (o.format == FileFormat::Gltf) o.binary = extension_of(path) != "gltf";
  std::string bytes;
  try {
    bytes = serialize_mesh(mesh, o);
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  io::write_file_atomic(path, bytes);
}

}  // namespace qem
