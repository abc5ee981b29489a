// The viewer's static server on cpp-httplib: the HTTP module (http_backend.h says why it is one).
#include <httplib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "view/http_backend.h"

namespace qem::view {

namespace {

// Connections served at once; more wait in the queue.
constexpr std::size_t kWorkers = 32;

class Server final : public HttpBackend {
 public:
  Server(const FileSet& files, const char* (*content_type)(const std::string&),
         std::atomic<std::size_t>& requests)
      : files_(files), content_type_(content_type), requests_(requests) {}
  // httplib::Server closes its socket when it stops listening but never one it bound and did not
  // listen on (a server constructed and destroyed without serve()).
  ~Server() override {
    if (!listened_ && http_.svr_sock_ != INVALID_SOCKET) ::close(http_.svr_sock_);
  }

  /// The port bound, or 0 when the port could not be bound.
  int bind(std::uint16_t port) {
    httplib::Server& s = http_;
    // httplib's default sets SO_REUSEPORT, with which a second `qem view` on the same port would
    // bind without error and silently take half of the first one's connections. SO_REUSEADDR alone
    // still lets a restarted `qem view` take the port back at once.
    s.set_socket_options([](socket_t sock) {
      int one = 1;
      ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    });
    s.new_task_queue = [] { return new httplib::ThreadPool(kWorkers); };
    s.set_keep_alive_max_count(1);  // one request per connection (see http_server.h)
    // The data changes from one `qem view` to the next on the same port: never cache.
    s.set_default_headers({{"Cache-Control", "no-store"}});
    s.set_pre_routing_handler([](const httplib::Request& req, httplib::Response& res) {
      if (req.method == "GET" || req.method == "HEAD") return httplib::Server::HandlerResponse::Unhandled;
      res.status = 405;
      res.set_header("Allow", "GET, HEAD");
      res.set_content("only GET and HEAD\n", "text/plain");
      return httplib::Server::HandlerResponse::Handled;
    });
    // HEAD is answered by the GET handler, without the body.
    s.Get("/.*", [this](const httplib::Request& req, httplib::Response& res) {
      std::string rel = req.path.substr(1);
      if (rel.empty() || rel.back() == '/') rel += "index.html";
      // Only exact keys of the in-memory set are served, so no path can reach the file system.
      auto it = files_.find(rel);
      if (it == files_.end()) {
        res.status = 404;
        res.set_content("not found: " + req.path + "\n", "text/plain");
        return;
      }
      res.set_content(it->second, content_type_(rel));
    });
    s.set_logger([this](const httplib::Request&, const httplib::Response&) { ++requests_; });
    const int bound = port == 0 ? s.bind_to_any_port(kLoopback) : s.bind_to_port(kLoopback, port) ? port : -1;
    port_ = bound > 0 ? std::uint16_t(bound) : 0;
    return port_;
  }

  std::uint16_t port() const override { return port_; }

  bool serve(const std::atomic<bool>& stop) override {
    std::atomic<bool> done{false}, ok{true};
    listened_ = true;
    std::thread listener([&] {
      ok = http_.listen_after_bind();
      done = true;
    });
    // The signal handler only sets `stop` (httplib's stop() is not async-signal-safe). A stop()
    // before the listener runs would be lost, so it is repeated until the listener has returned;
    // returning, it waits for the connections in flight.
    while (!done) {
      if (stop) http_.stop();
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    listener.join();
    return ok || stop;
  }

 private:
  // svr_sock_ is protected in httplib::Server: reached through a subclass.
  struct Http : httplib::Server {
    using httplib::Server::svr_sock_;
  } http_;
  const FileSet& files_;
  const char* (*content_type_)(const std::string&);
  std::atomic<std::size_t>& requests_;
  std::uint16_t port_ = 0;
  bool listened_ = false;
};

}  // namespace
}  // namespace qem::view

extern "C" __attribute__((visibility("default"))) qem::view::HttpBackend* qem_make_http_backend(
    const qem::view::FileSet& files, std::uint16_t port, const char* (*content_type)(const std::string&),
    std::atomic<std::size_t>& requests, std::string& error) {
  try {
    auto server = std::make_unique<qem::view::Server>(files, content_type, requests);
    if (server->bind(port) == 0) {
      error = std::string("cannot listen on ") + qem::view::kLoopback + ":" + std::to_string(port) +
              (port ? " (in use? try another --port, or --port 0 for any free port)" : "");
      return nullptr;
    }
    return server.release();
  } catch (const std::exception& e) {
    error = std::string("the HTTP server could not start: ") + e.what();
    return nullptr;
  }
}
