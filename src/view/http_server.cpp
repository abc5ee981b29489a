// The viewer's static server (http_server.h) on cpp-httplib.
#include "view/http_server.h"

#include <httplib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "qem/error.h"

namespace qem::view {

namespace {

constexpr const char* kLoopback = "127.0.0.1";  // by design: never another interface
// Connections served at once; more wait in the queue.
constexpr std::size_t kWorkers = 32;

}  // namespace

class HttpServer::Impl final : public httplib::Server {
 public:
  bool listened = false;
  // httplib::Server closes its socket when it stops listening but never one it bound and did not
  // listen on (a server constructed and destroyed without serve()).
  ~Impl() override {
    if (!listened && svr_sock_ != INVALID_SOCKET) ::close(svr_sock_);
  }
};

HttpServer::HttpServer(FileSet files, std::uint16_t port)
    : files_(std::move(files)), server_(std::make_unique<Impl>()) {
  httplib::Server& s = *server_;
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
    res.set_content(it->second, content_type(rel));
  });
  s.set_logger([this](const httplib::Request&, const httplib::Response&) { ++requests_; });

  const int bound = port == 0 ? s.bind_to_any_port(kLoopback) : s.bind_to_port(kLoopback, port) ? port : -1;
  if (bound <= 0)
    throw Error(std::string("cannot listen on ") + kLoopback + ":" + std::to_string(port) +
                (port ? " (in use? try another --port, or --port 0 for any free port)" : ""));
  port_ = static_cast<std::uint16_t>(bound);
}

HttpServer::~HttpServer() = default;

std::string HttpServer::url() const {
  return std::string("http://") + kLoopback + ":" + std::to_string(port_) + "/";
}

void HttpServer::serve(const std::atomic<bool>& stop) {
  std::atomic<bool> done{false}, ok{true};
  server_->listened = true;
  std::thread listener([&] {
    ok = server_->listen_after_bind();
    done = true;
  });
  // The signal handler only sets `stop` (httplib's stop() is not async-signal-safe). A stop()
  // before the listener runs would be lost, so it is repeated until the listener has returned;
  // returning, it waits for the connections in flight.
  while (!done) {
    if (stop) server_->stop();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  listener.join();
  if (!ok && !stop) throw Error("the HTTP server on " + url() + " stopped: it could not accept connections");
}

}  // namespace qem::view
