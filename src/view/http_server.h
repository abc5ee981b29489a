// The local HTTP server of `qem view`: serves a FileSet from memory, GET and HEAD only, on
// 127.0.0.1 only (never another interface: the page is for the local user). Requests are parsed by
// cpp-httplib, a maintained parser, not by code of our own. Each connection is answered once and
// closed, and up to 32 are served at once, so a browser's idle pre-connected sockets (dropped after
// httplib's 5 s timeout) never hold up the requests that matter. The server on cpp-httplib is a
// module loaded when the first HttpServer is made (http_backend.h says why), looked for, in order:
//   1. <folder of the executable>/libqem_http.so        (build/qem beside build/libqem_http.so)
//   2. <folder of the executable>/../<libdir>/qem/libqem_http.so  (an installed tree)
//   3. the build tree's, from the QEM_HTTP_MODULE_BUILT compile definition (the test programs)
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "view/web_assets.h"

namespace qem::view {

class HttpBackend;

/// Where the HTTP module is looked for, in order (see above).
std::vector<std::string> http_module_candidates();

class HttpServer {
 public:
  /// Binds 127.0.0.1:`port` (0 = any free port). Throws qem::Error on failure (e.g. port in use,
  /// or no HTTP module found).
  HttpServer(FileSet files, std::uint16_t port);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  /// The port actually bound.
  std::uint16_t port() const;
  /// "http://127.0.0.1:PORT/".
  std::string url() const;
  /// Answers requests until `stop` becomes true (checked at least every 100 ms), then waits for
  /// the connections in flight. Throws qem::Error if the server fails before that.
  void serve(const std::atomic<bool>& stop);
  /// The number of requests answered so far (for tests and the log).
  std::size_t requests() const { return requests_.load(); }

 private:
  // Before server_, which reads them until it is destroyed.
  FileSet files_;
  std::atomic<std::size_t> requests_{0};
  std::unique_ptr<HttpBackend> server_;
};

}  // namespace qem::view
