// Resolving files that a model references, inside its folder only (safe_path.h).
#include "view/safe_path.h"

#include <algorithm>
#include <system_error>

namespace fs = std::filesystem;

namespace qem::view {

namespace {

// True when the (normalised, relative) path climbs out of where it starts.
bool leaves(const fs::path& rel) { return rel.empty() || *rel.begin() == ".."; }

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

std::optional<ResolvedFile> resolve_inside(const fs::path& folder, const std::string& ref, std::string* why) {
  auto fail = [&](const char* reason) -> std::optional<ResolvedFile> {
    if (why) *why = reason;
    return std::nullopt;
  };
  std::string r = ref;
  std::replace(r.begin(), r.end(), '\\', '/');  // Windows tools write "textures\\skin.png"
  if (r.empty()) return fail("an empty file name");
  if (r.find('\0') != std::string::npos) return fail("a file name with a NUL byte");
  const fs::path p(r);
  if (p.is_absolute() || p.has_root_name() || r.front() == '/')
    return fail("an absolute path (only files in the model's folder are served)");
  const fs::path norm = p.lexically_normal();
  if (leaves(norm) || norm == ".") return fail("a path outside the model's folder");
  std::error_code ec;
  const fs::path base = fs::canonical(folder.empty() ? fs::path(".") : folder, ec);
  if (ec) return fail("the model's folder cannot be read");
  const fs::path real = fs::canonical(base / norm, ec);
  if (ec) return fail("no such file");
  // A symbolic link inside the folder may still lead out of it.
  if (leaves(real.lexically_relative(base))) return fail("a link to a file outside the model's folder");
  if (!fs::is_regular_file(real, ec)) return fail("not a regular file");
  return ResolvedFile{norm.generic_string(), real};
}

std::string percent_decode(const std::string& uri) {
  std::string out;
  out.reserve(uri.size());
  for (std::size_t i = 0; i < uri.size(); ++i) {
    int hi, lo;
    if (uri[i] == '%' && i + 2 < uri.size() && (hi = hex_value(uri[i + 1])) >= 0 &&
        (lo = hex_value(uri[i + 2])) >= 0) {
      out += static_cast<char>(hi * 16 + lo);
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

}  // namespace qem::view
