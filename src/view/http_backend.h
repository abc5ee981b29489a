// Between the viewer's server (http_server.h) and its HTTP module. cpp-httplib, as Debian builds
// it, brings OpenSSL, brotli and zlib with it, and loading and starting those was more than half
// of the start of every qem run, whether it served a page or not: so the server
// on cpp-httplib is a module of its own (libqem_http.so, src/view/http_module.cpp), loaded only
// when `qem view` serves.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>

#include "view/web_assets.h"

namespace qem::view {

/// The only interface served on, by design: the page is for the local user.
inline constexpr const char* kLoopback = "127.0.0.1";

class HttpBackend {
 public:
  virtual ~HttpBackend() = default;
  /// The port bound.
  virtual std::uint16_t port() const = 0;
  /// Answers requests until `stop` becomes true, then waits for the connections in flight; false
  /// if the server stopped by itself (it could not accept connections).
  virtual bool serve(const std::atomic<bool>& stop) = 0;
};

/// The module's entry point, kHttpModuleEntry (extern "C"): a server bound to 127.0.0.1:`port`
/// (0: any free port) answering GET and HEAD from `files` (which it reads until destroyed), with
/// `content_type`'s types, counting the requests answered in `requests`. On failure: null, and
/// `error` says why.
using MakeHttpBackend = HttpBackend* (*)(const FileSet& files, std::uint16_t port,
                                        const char* (*content_type)(const std::string&),
                                        std::atomic<std::size_t>& requests, std::string& error);
inline constexpr const char* kHttpModuleEntry = "qem_make_http_backend";
inline constexpr const char* kHttpModuleFile = "libqem_http.so";

}  // namespace qem::view
