// The command line's large allocations carry the advice for transparent huge pages
// (cli/huge_pages.h); the test binary links the same operator new.
#include "huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>
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
