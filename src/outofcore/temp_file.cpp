#include "outofcore/temp_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <mutex>

#include "qem/error.h"

namespace qem::outofcore {
namespace {

constexpr std::size_t kBufferBytes = std::size_t(4) << 20;

// Paths to remove when SIGINT or SIGTERM arrives. The handler may only make async-signal-safe
// calls (unlink, sigaction, raise), so the paths live in fixed arrays, not in std::strings.
constexpr int kSlots = 64;
constexpr std::size_t kPathMax = 4096;
char g_paths[kSlots][kPathMax];
std::atomic<bool> g_used[kSlots];
struct sigaction g_previous[2];
std::once_flag g_install_once;
std::atomic<std::uint64_t> g_temp_bytes{0};
std::atomic<std::uint64_t> g_fail_after{0};  // 0: no injected failure

extern "C" void remove_temp_files_and_reraise(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (g_used[i].load()) ::unlink(g_paths[i]);
  // Then die of the same signal with the handler that was there before, so the exit status says
  // how the process ended.
  ::sigaction(sig, &g_previous[sig == SIGINT ? 0 : 1], nullptr);
  ::raise(sig);
}

int register_path(const std::string& path) {
  std::call_once(g_install_once, [] {
    struct sigaction sa {};
    sa.sa_handler = remove_temp_files_and_reraise;
    sigemptyset(&sa.sa_mask);
    ::sigaction(SIGINT, &sa, &g_previous[0]);
    ::sigaction(SIGTERM, &sa, &g_previous[1]);
  });
  if (path.size() >= kPathMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (g_used[i].load() || !g_used[i].compare_exchange_strong(expected, true)) continue;
    // Filled after claiming: the handler may see a partial path for an instant, unlinking nothing.
    std::memcpy(g_paths[i], path.c_str(), path.size() + 1);
    return i;
  }
  return -1;
}

void unregister_path(int slot) {
  if (slot >= 0) g_used[slot].store(false);
}

std::string unique_name(const std::string& folder, const std::string& stem) {
  static std::atomic<unsigned> counter{0};
  auto now = static_cast<unsigned long long>(std::chrono::steady_clock::now().time_since_epoch().count());
  std::string dir = folder.empty() ? std::string(".") : folder;
  if (dir.back() != '/') dir += '/';
  return dir + ".qem-" + stem + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" +
         std::to_string(now % 1000000007ull);
}

}  // namespace

// --- BufferedWriter -------------------------------------------------------------------------------

BufferedWriter::~BufferedWriter() {
  close_fd();
  delete[] buffer_;
}

void BufferedWriter::open(const std::string& path, const std::string& what) {
  path_ = path;
  what_ = what;
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd_ < 0) throw Error(path + ": cannot create " + what + ": " + std::strerror(errno));
  buffer_ = new char[kBufferBytes];
}

void BufferedWriter::close_fd() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void BufferedWriter::drain() {
  if (is_temp_) {
    const std::uint64_t limit = g_fail_after.load();
    if (limit > 0 && g_temp_bytes.load() + used_ >= limit)
      throw Error(path_ + ": cannot write " + what_ + ": " + std::strerror(ENOSPC) + " (injected)");
  }
  std::size_t done = 0;
  while (done < used_) {
    ssize_t n = ::write(fd_, buffer_ + done, used_ - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error(path_ + ": cannot write " + what_ + ": " + std::strerror(errno));
    done += static_cast<std::size_t>(n);
  }
  written_ += used_;
  if (is_temp_) g_temp_bytes += used_;
  used_ = 0;
}

void BufferedWriter::write(const void* data, std::size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    if (used_ == kBufferBytes) drain();
    std::size_t k = std::min(n, kBufferBytes - used_);
    std::memcpy(buffer_ + used_, p, k);
    used_ += k, p += k, n -= k;
  }
}

void BufferedWriter::flush() {
  drain();
  if (::fsync(fd_) != 0 && errno != EINVAL && errno != EROFS)
    throw Error(path_ + ": cannot flush " + what_ + ": " + std::strerror(errno));
}

// --- TempFile -------------------------------------------------------------------------------------

TempFile::TempFile(const std::string& folder, const std::string& stem) {
  struct stat st {};
  if (::stat(folder.c_str(), &st) != 0)
    throw Error("temporary folder " + folder + ": " + std::strerror(errno) +
                " (choose another with --temp-dir)");
  if (!S_ISDIR(st.st_mode))
    throw Error("temporary folder " + folder + ": not a folder (choose another with --temp-dir)");
  const std::string path = unique_name(folder, stem);
  is_temp_ = true;
  slot_ = register_path(path);  // before creating it: an interrupt in between unlinks nothing harmful
  try {
    open(path, "a temporary file (in the folder of --temp-dir)");
  } catch (...) {
    unregister_path(slot_);
    throw;
  }
}

TempFile::~TempFile() {
  close_fd();
  ::unlink(path_.c_str());
  unregister_path(slot_);
}

void TempFile::rewind_for_reading() {
  // Without fsync: the data is read back by this process through the page cache.
  drain();
  if (::lseek(fd_, 0, SEEK_SET) != 0) throw Error(path_ + ": cannot rewind: " + std::strerror(errno));
}

std::size_t TempFile::read(void* data, std::size_t n) {
  std::size_t done = 0;
  while (done < n) {
    ssize_t k = ::read(fd_, static_cast<char*>(data) + done, n - done);
    if (k < 0 && errno == EINTR) continue;
    if (k < 0) throw Error(path_ + ": cannot read back: " + std::strerror(errno));
    if (k == 0) break;
    done += static_cast<std::size_t>(k);
  }
  return done;
}

void TempFile::read_at(std::uint64_t offset, void* data, std::size_t n) const {
  std::size_t done = 0;
  while (done < n) {
    ssize_t k = ::pread(fd_, static_cast<char*>(data) + done, n - done, off_t(offset + done));
    if (k < 0 && errno == EINTR) continue;
    if (k < 0) throw Error(path_ + ": cannot read back: " + std::strerror(errno));
    if (k == 0) throw Error(path_ + ": cannot read back: the file ends early");
    done += static_cast<std::size_t>(k);
  }
}

// --- AtomicOutput ---------------------------------------------------------------------------------

AtomicOutput::AtomicOutput(const std::string& path) : target_(path) {
  if (path.empty()) throw Error("cannot write: empty file name");
  std::string dir = ".";
  if (auto slash = path.find_last_of('/'); slash != std::string::npos) dir = path.substr(0, slash + 1);
  std::string base =
      path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
  const std::string tmp = unique_name(dir, base + ".tmp");
  slot_ = register_path(tmp);
  try {
    open(tmp, "the output (a temporary file beside it)");
  } catch (...) {
    unregister_path(slot_);
    throw;
  }
}

AtomicOutput::~AtomicOutput() {
  close_fd();
  if (!committed_) ::unlink(path_.c_str());
  unregister_path(slot_);
}

void AtomicOutput::commit() {
  flush();
  close_fd();
  if (::rename(path_.c_str(), target_.c_str()) != 0)
    throw Error(target_ + ": cannot replace the file: " + std::strerror(errno));
  committed_ = true;
}

std::uint64_t temp_bytes_written() { return g_temp_bytes.load(); }

void inject_write_failure_after(std::uint64_t bytes) { g_fail_after = bytes; }

}  // namespace qem::outofcore
