// Locates the built viewer page and moves file sets between disk and memory (web_assets.h).
#include "view/web_assets.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "qem/error.h"

namespace fs = std::filesystem;

namespace qem::view {

namespace {

bool has_page(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(dir / "index.html", ec) && fs::is_regular_file(dir / "app.js", ec);
}

}  // namespace

std::string executable_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.parent_path().string();
}

std::vector<std::string> web_asset_candidates() {
  std::vector<std::string> out;
  if (const char* env = std::getenv("QEM_WEB_DIR"); env && *env) out.push_back(env);
  const fs::path dir = executable_dir();
  if (!dir.empty()) {
    out.push_back((dir / "web").string());
    out.push_back((dir / ".." / "share" / "qem" / "web").lexically_normal().string());
  }
#ifdef QEM_WEB_DIST_DIR
  out.push_back(QEM_WEB_DIST_DIR);
#endif
  if (!dir.empty()) out.push_back((dir / ".." / "web" / "dist").lexically_normal().string());
  return out;
}

std::string find_web_assets() {
  std::vector<std::string> candidates = web_asset_candidates();
  for (const std::string& c : candidates)
    if (has_page(c)) return c;
  std::string looked;
  for (const std::string& c : candidates) looked += (looked.empty() ? "" : ", ") + c;
  throw Error(
      "the viewer page is not built (no index.html + app.js in: " + looked +
      "). Build it with `scripts/install-web-deps.sh && (cd web && npm run build)`, or set QEM_WEB_DIR to "
      "a folder holding the built page");
}

FileSet read_tree(const std::string& dir) {
  FileSet files;
  std::error_code ec;
  fs::recursive_directory_iterator it(dir, fs::directory_options::follow_directory_symlink, ec), end;
  if (ec) throw Error(dir + ": cannot read the folder: " + ec.message());
  for (; it != end; it.increment(ec)) {
    if (ec) throw Error(dir + ": cannot read the folder: " + ec.message());
    if (!it->is_regular_file()) continue;
    std::ifstream in(it->path(), std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    if (!in) throw Error(it->path().string() + ": cannot read");
    files[fs::relative(it->path(), dir).generic_string()] = ss.str();
  }
  return files;
}

void write_tree(const std::string& dir, const FileSet& files) {
  for (const auto& [rel, bytes] : files) {
    fs::path p = fs::path(dir) / rel;
    std::error_code ec;
    fs::create_directories(p.parent_path(), ec);
    if (ec) throw Error(p.parent_path().string() + ": cannot create the folder: " + ec.message());
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw Error(p.string() + ": cannot write");
  }
}

const char* content_type(const std::string& path) {
  auto ends = [&](const char* ext) {
    std::string e(ext);
    return path.size() >= e.size() && path.compare(path.size() - e.size(), e.size(), e) == 0;
  };
  if (ends(".html")) return "text/html; charset=utf-8";
  if (ends(".js") || ends(".mjs")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  if (ends(".json")) return "application/json";
  if (ends(".png") || ends(".PNG")) return "image/png";
  if (ends(".jpg") || ends(".jpeg") || ends(".JPG") || ends(".JPEG")) return "image/jpeg";
  if (ends(".webp")) return "image/webp";
  if (ends(".ktx2")) return "image/ktx2";
  if (ends(".gltf")) return "model/gltf+json";
  if (ends(".glb")) return "model/gltf-binary";
  if (ends(".svg")) return "image/svg+xml";
  if (ends(".txt")) return "text/plain; charset=utf-8";
  return "application/octet-stream";
}

}  // namespace qem::view
