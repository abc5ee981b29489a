// The viewer's static server (src/view/http_server.h) answering real requests on 127.0.0.1.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "qem/error.h"
#include "view/http_server.h"

namespace qem::view {
namespace {

/// Sends one raw request to 127.0.0.1:port and returns the whole response.
std::string request(std::uint16_t port, const std::string& raw) {
  int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return "connect failed";
  }
  ::send(fd, raw.data(), raw.size(), MSG_NOSIGNAL);
  std::string out;
  char buf[4096];
  ssize_t n;
  while ((n = ::recv(fd, buf, sizeof buf, 0)) > 0) out.append(buf, static_cast<std::size_t>(n));
  ::close(fd);
  return out;
}

class ViewHttp : public ::testing::Test {
 protected:
  void SetUp() override {
    FileSet files{{"index.html", "<html>hello</html>"},
                  {"data/scene.json", "{}"},
                  {"data/level0.pos.f32", std::string("\0\x01\x02", 3)},
                  {"data/level0/tex/a b.png", "PNG"},
                  {"data/level1/man.glb", "glTF"}};
    server_ = std::make_unique<HttpServer>(files, 0);
    thread_ = std::thread([this] { server_->serve(stop_); });
  }
  void TearDown() override {
    stop_ = true;
    thread_.join();
  }
  std::string get(const std::string& path) {
    return request(server_->port(), "GET " + path + " HTTP/1.1\r\nHost: x\r\n\r\n");
  }

  std::atomic<bool> stop_{false};
  std::unique_ptr<HttpServer> server_;
  std::thread thread_;
};

TEST_F(ViewHttp, ServesFilesWithTypesAndLengths) {
  EXPECT_NE(server_->port(), 0);
  EXPECT_EQ(server_->url(), "http://127.0.0.1:" + std::to_string(server_->port()) + "/");
  std::string r = get("/");
  EXPECT_EQ(r.rfind("HTTP/1.1 200 OK\r\n", 0), 0u) << r;
  EXPECT_NE(r.find("Content-Type: text/html"), std::string::npos);
  EXPECT_NE(r.find("Content-Length: 18\r\n"), std::string::npos);
  EXPECT_EQ(r.substr(r.size() - 18), "<html>hello</html>");
  EXPECT_NE(r.find("Cache-Control: no-store\r\n"), std::string::npos);  // the data changes between runs
  r = get("/data/scene.json?x=1");
  EXPECT_NE(r.find("application/json"), std::string::npos) << r;
  r = get("/data/level0.pos.f32");
  EXPECT_EQ(r.substr(r.size() - 3), std::string("\0\x01\x02", 3));
  EXPECT_GE(server_->requests(), 3u);
}

TEST_F(ViewHttp, ServesAModelsFilesByTheirEscapedNames) {
  std::string r = get("/data/level0/tex/a%20b.png");
  EXPECT_EQ(r.rfind("HTTP/1.1 200", 0), 0u) << r;
  EXPECT_NE(r.find("Content-Type: image/png\r\n"), std::string::npos) << r;
  EXPECT_EQ(r.substr(r.size() - 3), "PNG");
  r = get("/data/level1/man.glb");
  EXPECT_NE(r.find("Content-Type: model/gltf-binary\r\n"), std::string::npos) << r;
  // Escaped dots name no key: nothing outside the set, nothing by another path.
  EXPECT_EQ(get("/data/level0/tex/%2e%2e/%2e%2e/scene.json").rfind("HTTP/1.1 404", 0), 0u);
  EXPECT_EQ(get("/data/level0/tex/..%2f..%2fscene.json").rfind("HTTP/1.1 404", 0), 0u);
}

TEST_F(ViewHttp, AnswersErrorsWithoutTouchingTheFileSystem) {
  EXPECT_EQ(get("/missing.js").rfind("HTTP/1.1 404", 0), 0u);
  EXPECT_EQ(get("/../../etc/passwd").rfind("HTTP/1.1 404", 0), 0u);
  std::string post = request(server_->port(), "POST / HTTP/1.1\r\nContent-Length: 3\r\n\r\nabc");
  EXPECT_EQ(post.rfind("HTTP/1.1 405", 0), 0u) << post;
  EXPECT_NE(post.find("Allow: GET, HEAD\r\n"), std::string::npos);
  EXPECT_EQ(request(server_->port(), "garbage\r\n\r\n").rfind("HTTP/1.1 400", 0), 0u);
  std::string head = request(server_->port(), "HEAD /index.html HTTP/1.1\r\n\r\n");
  EXPECT_EQ(head.rfind("HTTP/1.1 200", 0), 0u);
  EXPECT_EQ(head.find("hello"), std::string::npos);  // HEAD: headers only
}

TEST_F(ViewHttp, AClientThatSaysNothingDoesNotBlockOthers) {
  // A browser pre-connects sockets it may never use; other requests must still be answered.
  int idle = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(server_->port());
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(idle, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(get("/").rfind("HTTP/1.1 200", 0), 0u);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
  ::close(idle);
}

TEST(ViewHttpBind, APortInUseIsAClearError) {
  HttpServer server({}, 0);
  // The port is taken on 127.0.0.1: a second server on it must throw qem::Error, not crash, and
  // not share the port either (httplib's default SO_REUSEPORT would let it).
  EXPECT_THROW(HttpServer({}, server.port()), Error);
}

TEST(ViewHttpBind, AServerDestroyedWithoutServingFreesItsPort) {
  std::uint16_t port = 0;
  {
    HttpServer unused({}, 0);
    port = unused.port();
  }
  EXPECT_NO_THROW(HttpServer({}, port));
}

// The server is a module (http_backend.h): looked for beside the program first, each place once,
// and found in this build.
TEST(ViewHttpModule, LookedForBesideTheProgramFirstAndFoundInTheBuild) {
  const std::vector<std::string> candidates = http_module_candidates();
  ASSERT_FALSE(candidates.empty());
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe");
  EXPECT_EQ(candidates.front(), (exe.parent_path() / "libqem_http.so").string());
  for (std::size_t i = 0; i < candidates.size(); ++i)
    for (std::size_t j = i + 1; j < candidates.size(); ++j) EXPECT_NE(candidates[i], candidates[j]);
  EXPECT_TRUE(std::any_of(candidates.begin(), candidates.end(),
                          [](const std::string& c) { return std::filesystem::is_regular_file(c); }));
}

}  // namespace
}  // namespace qem::view
