// Files written while a run streams: a temporary file in a chosen folder that is removed when it is
// destroyed (success, failure, exception) and, through a SIGINT/SIGTERM handler, when the process
// is interrupted; and an output written beside its target and renamed over it only when complete
// (as io/atomic_file.cpp does for a mesh held in memory), so a failed run leaves nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace qem::outofcore {

/// A file opened for writing with a buffer; every failure (full disk, unwritable folder) throws
/// qem::Error naming the file and the reason.
class BufferedWriter {
 public:
  BufferedWriter() = default;
  ~BufferedWriter();
  BufferedWriter(const BufferedWriter&) = delete;
  BufferedWriter& operator=(const BufferedWriter&) = delete;

  void write(const void* data, std::size_t n);
  template <class T>
  void put(const T& value) {
    write(&value, sizeof(T));
  }
  /// Writes the buffer out and fsyncs; the file stays open.
  void flush();
  std::uint64_t bytes_written() const { return written_ + used_; }
  const std::string& path() const { return path_; }

 protected:
  void open(const std::string& path, const std::string& what);
  void close_fd();
  void drain();

  std::string path_, what_;
  int fd_ = -1;
  char* buffer_ = nullptr;
  std::size_t used_ = 0;
  std::uint64_t written_ = 0;
  bool is_temp_ = false;  ///< counted in temp_bytes_written(), subject to the injected failure
};

/// A uniquely named temporary file in `folder`, removed by its destructor and on SIGINT/SIGTERM.
class TempFile : public BufferedWriter {
 public:
  /// `stem` names the file's role ("faces"); throws qem::Error when the folder is not writable.
  TempFile(const std::string& folder, const std::string& stem);
  ~TempFile();
  /// Flushes the writes and reopens the file for reading from the start (read()).
  void rewind_for_reading();
  /// Reads up to n bytes; returns how many (0 at the end).
  std::size_t read(void* data, std::size_t n);
  /// After rewind_for_reading: reads n bytes at `offset`, from any thread (it moves no file
  /// position); fewer than n is an error naming the file.
  void read_at(std::uint64_t offset, void* data, std::size_t n) const;

 private:
  int slot_ = -1;
};

/// The target of a streamed output: writes go to a temporary file beside `path`, commit() flushes
/// and renames it over `path`; destroyed without commit() (an exception), the temporary is removed.
class AtomicOutput : public BufferedWriter {
 public:
  explicit AtomicOutput(const std::string& path);
  ~AtomicOutput();
  void commit();

 private:
  std::string target_;
  int slot_ = -1;
  bool committed_ = false;
};

/// Total bytes written to temporary files by this process so far.
std::uint64_t temp_bytes_written();

/// Test hook: after this many more bytes written to TempFiles, the next write fails as a full disk
/// would (ENOSPC). 0 turns it off.
void inject_write_failure_after(std::uint64_t bytes);

}  // namespace qem::outofcore
