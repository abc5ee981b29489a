// The viewer's static server (http_server.h): the HTTP module (http_backend.h) loaded and asked
// for a server.
#include "view/http_server.h"

#include <dlfcn.h>

#include <algorithm>
#include <filesystem>
#include <mutex>
#include <vector>

#include "qem/error.h"
#include "view/http_backend.h"

namespace qem::view {

namespace {

// The module's entry point, from the first candidate that loads (http_server.h lists them). The
// module stays loaded until the program ends.
MakeHttpBackend load_module() {
  static std::once_flag once;
  static MakeHttpBackend make = nullptr;
  static std::string failure;
  std::call_once(once, [] {
    std::string tried;
    for (const std::string& path : http_module_candidates()) {
      std::error_code ec;
      if (!std::filesystem::is_regular_file(path, ec)) {
        tried += "\n  " + path + " (not there)";
        continue;
      }
      void* module = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!module) {
        const char* why = dlerror();
        tried += "\n  " + path + " (" + (why ? why : "cannot be loaded") + ")";
        continue;
      }
      make = reinterpret_cast<MakeHttpBackend>(dlsym(module, kHttpModuleEntry));
      if (make) return;
      tried += "\n  " + path + " (no " + kHttpModuleEntry + " in it)";
    }
    failure = std::string("qem view serves through its HTTP module, ") + kHttpModuleFile +
              ", which was not found where it is looked for:" + tried +
              "\n(build the project's qem_http target, or use --export to write the page to a folder)";
  });
  if (!make) throw Error(failure);
  return make;
}

}  // namespace

std::vector<std::string> http_module_candidates() {
  std::vector<std::string> out;
  const std::filesystem::path dir = executable_dir();
  if (!dir.empty()) {
    out.push_back((dir / kHttpModuleFile).string());
#ifdef QEM_HTTP_MODULE_FROM_BINDIR
    out.push_back((dir / QEM_HTTP_MODULE_FROM_BINDIR).lexically_normal().string());
#endif
  }
#ifdef QEM_HTTP_MODULE_BUILT
  if (std::find(out.begin(), out.end(), QEM_HTTP_MODULE_BUILT) == out.end())
    out.push_back(QEM_HTTP_MODULE_BUILT);
#endif
  return out;
}

HttpServer::HttpServer(FileSet files, std::uint16_t port) : files_(std::move(files)) {
  const MakeHttpBackend make = load_module();
  std::string error;
  server_.reset(make(files_, port, &content_type, requests_, error));
  if (!server_) throw Error(error);
}

std::uint16_t HttpServer::port() const { return server_->port(); }

HttpServer::~HttpServer() = default;

std::string HttpServer::url() const {
  return std::string("http://") + kLoopback + ":" + std::to_string(port()) + "/";
}

void HttpServer::serve(const std::atomic<bool>& stop) {
  if (!server_->serve(stop)) throw Error("the HTTP server on " + url() + " stopped: it could not accept connections");
}

}  // namespace qem::view
