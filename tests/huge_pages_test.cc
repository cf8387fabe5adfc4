// Host grids on transparent huge pages (vasco_gpu/src/huge_pages.h): the
// cells are what assign gives, the allocation is kept while the size does not
// grow, and where the system grants huge pages on request (THP "madvise" or
// "always"), a grid's pages are huge ones: /proc/self/smaps counts them.
#include "huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

// The THP mode the kernel names in brackets ("always [madvise] never"), or "".
std::string thp_mode() {
  std::ifstream f("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  if (!std::getline(f, line)) return "";
  const size_t a = line.find('['), b = line.find(']');
  return a == std::string::npos || b == std::string::npos ? "" : line.substr(a + 1, b - a - 1);
}

// AnonHugePages (kB) of the mapping that holds address p.
long huge_kb_at(const void *p) {
  std::ifstream f("/proc/self/smaps");
  const auto at = reinterpret_cast<uintptr_t>(p);
  std::string line;
  bool inside = false;
  while (std::getline(f, line)) {
    uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
      inside = lo <= at && at < hi;
      continue;
    }
    if (inside && line.rfind("AnonHugePages:", 0) == 0) return std::stol(line.substr(14));
  }
  return -1;
}

TEST(HugePages, AssignGivesTheCellsAndKeepsTheAllocationWhileTheSizeDoesNotGrow) {
  std::vector<float> v;
  const size_t n = size_t(3) << 20;  // 12 MiB of floats
  vasco::assign_on_huge_pages(v, n, -1.0f);
  ASSERT_EQ(v.size(), n);
  for (size_t i = 0; i < n; i += 4099) ASSERT_EQ(v[i], -1.0f) << i;
  const float *first = v.data();
  vasco::assign_on_huge_pages(v, n / 2, 0.5f);
  EXPECT_EQ(v.data(), first);  // smaller: the same allocation
  ASSERT_EQ(v.size(), n / 2);
  EXPECT_EQ(v.back(), 0.5f);
  vasco::assign_on_huge_pages(v, n * 2, 2.0f);  // larger: a new one, every cell given
  ASSERT_EQ(v.size(), n * 2);
  for (size_t i = 0; i < v.size(); i += 4099) ASSERT_EQ(v[i], 2.0f) << i;
  std::vector<float> roomy;
  vasco::assign_on_huge_pages(roomy, n, -1.0f, n + n / 8);
  EXPECT_GE(roomy.capacity(), n + n / 8);
  const float *at = roomy.data();
  vasco::assign_on_huge_pages(roomy, n + n / 8, 3.0f);  // grown into its room: the same allocation
  EXPECT_EQ(roomy.data(), at);
  for (size_t i = 0; i < roomy.size(); i += 4099) ASSERT_EQ(roomy[i], 3.0f) << i;
  std::vector<float> small;
  vasco::assign_on_huge_pages(small, 10, 1.0f);  // under the advice's size: plain assign
  EXPECT_EQ(small, std::vector<float>(10, 1.0f));
}

TEST(HugePages, AGridOfMegabytesIsOnHugePagesWhereTheSystemGrantsThem) {
  const std::string mode = thp_mode();
  if (mode != "madvise" && mode != "always") GTEST_SKIP() << "transparent huge pages are '" << mode << "' here";
  std::vector<float> grid;
  vasco::assign_on_huge_pages(grid, size_t(16) << 20, -1.0f);  // 64 MiB
  const long kb = huge_kb_at(grid.data() + grid.size() / 2);
  // Under "madvise" only the advice gets huge pages at the first touch; a
  // fragmented memory may give fewer than all, rarely none of 32 (defrag
  // "madvise" compacts for advised regions at fault time).
  EXPECT_GT(kb, 0) << "no huge page in the grid's mapping (THP " << mode << ")";
}

}  // namespace
