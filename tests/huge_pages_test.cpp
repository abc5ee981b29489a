// The command line's large allocations carry the advice for transparent huge pages
// (cli/huge_pages.h); the test binary links the same operator new.
#include "huge_pages.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace qem::cli;

TEST(HugePages, TheWholeHugePagesInsideABlock) {
  const std::uintptr_t two = kHugePageBytes;
  const auto range = [](std::uintptr_t at, std::size_t bytes) {
    return whole_huge_pages(reinterpret_cast<const void*>(at), bytes);
  };
  // Aligned: every page; one byte off at either end: one page fewer.
  EXPECT_EQ(range(4 * two, 3 * two).begin, 4 * two);
  EXPECT_EQ(range(4 * two, 3 * two).end, 7 * two);
  EXPECT_EQ(range(4 * two + 16, 3 * two).begin, 5 * two);
  EXPECT_EQ(range(4 * two + 16, 3 * two).end, 7 * two);
  EXPECT_EQ(range(4 * two, 3 * two - 1).end, 6 * two);
  // Less than a whole page inside: empty, never reversed.
  const AddressRange none = range(4 * two + 16, two);
  EXPECT_EQ(none.begin, none.end);
  EXPECT_EQ(range(4 * two + 16, 100).begin, range(4 * two + 16, 100).end);
}

namespace {

// The VmFlags of the mapping of /proc/self/smaps that holds address `at` ("" if none).
std::string vm_flags_at(std::uintptr_t at) {
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-' && line.find(':') > line.find(' ')) {
      inside = lo <= at && at < hi;
      continue;
    }
    if (inside && line.rfind("VmFlags:", 0) == 0) return line;
  }
  return "";
}

}  // namespace

TEST(HugePages, ALargeArrayIsAdvised) {
  if (!kAdvisesHugePages) GTEST_SKIP() << "AddressSanitizer's build: the sanitizer's operator new";
  if (!std::filesystem::exists("/sys/kernel/mm/transparent_hugepage/enabled"))
    GTEST_SKIP() << "no transparent huge pages in this kernel";
  std::vector<char> large(3 * kAdvisedFromBytes);
  const AddressRange r = whole_huge_pages(large.data(), large.size());
  ASSERT_LT(r.begin, r.end);
  EXPECT_NE(vm_flags_at(r.begin).find(" hg"), std::string::npos) << vm_flags_at(r.begin);
  // A small one is left to the default (its pages are shared with other blocks).
  std::vector<char> small(kAdvisedFromBytes / 8);
  EXPECT_EQ(vm_flags_at(reinterpret_cast<std::uintptr_t>(small.data())).find(" hg"), std::string::npos);
}

TEST(HugePages, QemHugePagesZeroTurnsTheAdviceOff) {
  EXPECT_TRUE(huge_pages_wanted(nullptr));
  EXPECT_TRUE(huge_pages_wanted("1"));
  EXPECT_TRUE(huge_pages_wanted(""));
  EXPECT_FALSE(huge_pages_wanted("0"));
}

TEST(MallocTunables, AddedToTheUsersUnlessTheyTuneMalloc) {
  std::string storage;
  EXPECT_STREQ(tuned_malloc_environment(nullptr, storage), kMallocTunables);
  EXPECT_STREQ(tuned_malloc_environment("", storage), kMallocTunables);
  EXPECT_EQ(std::string(tuned_malloc_environment("glibc.cpu.x86_ibt=on", storage)),
            std::string("glibc.cpu.x86_ibt=on:") + kMallocTunables);
  EXPECT_EQ(tuned_malloc_environment("glibc.malloc.arena_max=2", storage), nullptr);
}

namespace {

// The mapping of /proc/self/maps that holds `at`, by its name ("" if it has none).
std::string mapping_name_at(std::uintptr_t at) {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line)) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream fields(line);
    if (!(fields >> std::hex >> lo >> dash >> hi) || !(lo <= at && at < hi)) continue;
    std::string permissions, offset, device, inode, name;
    fields >> permissions >> offset >> device >> inode >> name;
    return name.empty() ? "anonymous" : name;
  }
  return "";
}

constexpr const char* kReportTo = "QEM_TEST_MALLOC_REPORT";

}  // namespace

// The second start of MallocTunables.TheProgramStartsAgainWithThem (skipped on its own): what the
// tunables did and what the environment is after with_malloc_tunables put it back.
TEST(MallocTunables, SecondStart) {
  const char* report = std::getenv(kReportTo);
  if (!report) GTEST_SKIP() << "run by MallocTunables.TheProgramStartsAgainWithThem";
  with_malloc_tunables(nullptr);
  std::ofstream out(report);
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  out << "tunables " << (tunables ? tunables : "(none)") << "\n";
  out << "marker " << (std::getenv("QEM_MALLOC_TUNED") ? "set" : "gone") << "\n";
  // A block far above glibc's default mmap threshold comes from its heap: glibc read the tunables.
  void* block = std::malloc(std::size_t(64) << 20);
  out << "block " << mapping_name_at(reinterpret_cast<std::uintptr_t>(block)) << "\n";
  std::free(block);
}

TEST(MallocTunables, FromTheSizeOfTheLargestFileNamed) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "qem_malloc_tunables_sizes";
  std::filesystem::create_directories(dir);
  const std::filesystem::path small = dir / "small.ply", large = dir / "large.ply";
  std::ofstream(small) << std::string(100, 'x');
  std::ofstream(large) << std::string(5000, 'x');
  std::string program = "qem", command = "simplify", a = small.string(), b = large.string(),
              missing = "none.ply", folder = dir.string();
  char* both[] = {program.data(), command.data(), a.data(), b.data(), missing.data(), folder.data(), nullptr};
  EXPECT_EQ(largest_file_named(both), 5000u);
  char* neither[] = {program.data(), command.data(), missing.data(), folder.data(), nullptr};
  EXPECT_EQ(largest_file_named(neither), 0u);
  // The program's own file is not an argument.
  char* itself[] = {b.data(), a.data(), nullptr};
  EXPECT_EQ(largest_file_named(itself), 100u);
  std::filesystem::remove_all(dir);
}

TEST(MallocTunables, TheProgramStartsAgainWithThem) {
  if (!kAdvisesHugePages) GTEST_SKIP() << "AddressSanitizer's build keeps its allocator";
  if (!std::filesystem::exists("/proc/self/exe")) GTEST_SKIP() << "no /proc";
  const std::filesystem::path report =
      std::filesystem::temp_directory_path() / "qem_malloc_tunables_report.txt";
  std::filesystem::remove(report);
  std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    setenv(kReportTo, report.c_str(), 1);
    setenv("GLIBC_TUNABLES", "glibc.cpu.x86_ibt=on", 1);
    unsetenv("QEM_HUGE_PAGES");
    std::string filter = "--gtest_filter=MallocTunables.SecondStart";
    char* argv[] = {self.data(), filter.data(), nullptr};
    with_malloc_tunables(argv, 0);
    _exit(42);  // not started again
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 0);
  std::ifstream in(report);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("tunables glibc.cpu.x86_ibt=on\n"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("marker gone\n"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("block [heap]\n"), std::string::npos) << text.str();
  std::filesystem::remove(report);
}
