// A tiny HTTP/1.1 static file server for `qem view`: serves a FileSet from memory, GET and HEAD
// only, on 127.0.0.1 only (never another interface: the page is for the local user). Each
// connection is answered once and closed; one thread per connection so a browser's idle
// pre-connected sockets never hold up the requests that matter.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "view/web_assets.h"

namespace qem::view {

class HttpServer {
 public:
  /// Binds 127.0.0.1:`port` (0 = any free port) and listens. Throws qem::Error on failure.
  HttpServer(FileSet files, std::uint16_t port);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  /// The port actually bound.
  std::uint16_t port() const { return port_; }
  /// "http://127.0.0.1:PORT/".
  std::string url() const;
  /// Answers requests until `stop` becomes true (checked at least every 100 ms), then waits for
  /// the connections in flight.
  void serve(const std::atomic<bool>& stop);
  /// The number of requests answered so far (for tests and the log).
  std::size_t requests() const { return requests_.load(); }

 private:
  void handle(int fd);

  FileSet files_;
  int listen_fd_ = -1;
  std::uint16_t port_ = 0;
  std::atomic<std::size_t> requests_{0};
};

}  // namespace qem::view
