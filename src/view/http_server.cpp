// POSIX-socket implementation of the viewer's static server (http_server.h).
#include "view/http_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

#include "qem/error.h"

namespace qem::view {

namespace {

// A request head larger than this is not from a browser fetching a page.
constexpr std::size_t kMaxHead = 16 * 1024;
// Connections served at once; more wait in the listen backlog.
constexpr std::size_t kMaxThreads = 32;

void send_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    ssize_t n = ::send(fd, data, size, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // the client went away: nothing to do
    data += n;
    size -= static_cast<std::size_t>(n);
  }
}

void respond(int fd, int status, const char* reason, const char* type, const std::string& body,
             bool head_only) {
  std::string head = "HTTP/1.1 " + std::to_string(status) + " " + reason + "\r\n";
  head += std::string("Content-Type: ") + type + "\r\n";
  head += "Content-Length: " + std::to_string(body.size()) + "\r\n";
  // The data changes from one `qem view` to the next on the same port: never cache.
  head += "Cache-Control: no-store\r\nConnection: close\r\n";
  if (status == 405) head += "Allow: GET, HEAD\r\n";
  head += "\r\n";
  send_all(fd, head.data(), head.size());
  if (!head_only) send_all(fd, body.data(), body.size());
}

}  // namespace

HttpServer::HttpServer(FileSet files, std::uint16_t port) : files_(std::move(files)) {
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) throw Error(std::string("cannot create a socket: ") + std::strerror(errno));
  int one = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);  // 127.0.0.1 only, by design
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0 ||
      ::listen(listen_fd_, 64) < 0) {
    std::string why = std::strerror(errno);
    ::close(listen_fd_);
    throw Error("cannot listen on 127.0.0.1:" + std::to_string(port) + ": " + why +
                (port ? " (try another --port, or --port 0 for any free port)" : ""));
  }
  socklen_t len = sizeof addr;
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
}

HttpServer::~HttpServer() {
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

std::string HttpServer::url() const { return "http://127.0.0.1:" + std::to_string(port_) + "/"; }

void HttpServer::serve(const std::atomic<bool>& stop) {
  std::vector<std::thread> threads;
  std::vector<std::shared_ptr<std::atomic<bool>>> done;
  while (!stop.load()) {
    // Reap finished connection threads so a long session does not accumulate them.
    for (std::size_t i = 0; i < threads.size();) {
      if (done[i]->load()) {
        threads[i].join();
        threads.erase(threads.begin() + static_cast<std::ptrdiff_t>(i));
        done.erase(done.begin() + static_cast<std::ptrdiff_t>(i));
      } else {
        ++i;
      }
    }
    if (threads.size() >= kMaxThreads) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      continue;
    }
    pollfd p{listen_fd_, POLLIN, 0};
    int r = ::poll(&p, 1, 100);
    if (r <= 0) continue;  // timeout, or EINTR from the signal that sets `stop`
    int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd < 0) continue;
    auto flag = std::make_shared<std::atomic<bool>>(false);
    done.push_back(flag);
    threads.emplace_back([this, fd, flag] {
      handle(fd);
      ::close(fd);
      flag->store(true);
    });
  }
  for (std::thread& t : threads) t.join();
}

void HttpServer::handle(int fd) {
  // A client that connects and says nothing (a browser's pre-connect) is dropped after 5 s.
  timeval tv{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::string head;
  char buf[4096];
  while (head.find("\r\n\r\n") == std::string::npos) {
    if (head.size() > kMaxHead)
      return respond(fd, 431, "Request Header Fields Too Large", "text/plain", "", false);
    ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    head.append(buf, static_cast<std::size_t>(n));
  }
  ++requests_;
  std::size_t sp1 = head.find(' '), sp2 = sp1 == std::string::npos ? sp1 : head.find(' ', sp1 + 1);
  if (sp2 == std::string::npos || head.compare(sp2 + 1, 5, "HTTP/") != 0)
    return respond(fd, 400, "Bad Request", "text/plain", "bad request\n", false);
  std::string method = head.substr(0, sp1), target = head.substr(sp1 + 1, sp2 - sp1 - 1);
  bool head_only = method == "HEAD";
  if (method != "GET" && !head_only)
    return respond(fd, 405, "Method Not Allowed", "text/plain", "only GET and HEAD\n", false);
  if (std::size_t q = target.find_first_of("?#"); q != std::string::npos) target.resize(q);
  if (target.empty() || target[0] != '/')
    return respond(fd, 400, "Bad Request", "text/plain", "bad path\n", false);
  std::string rel = target.substr(1);
  if (rel.empty() || rel.back() == '/') rel += "index.html";
  // Only exact keys of the in-memory set are served, so no path can reach the file system.
  auto it = files_.find(rel);
  if (it == files_.end())
    return respond(fd, 404, "Not Found", "text/plain", "not found: " + target + "\n", head_only);
  respond(fd, 200, "OK", content_type(rel), it->second, head_only);
}

}  // namespace qem::view
