// CARMEN's own maps, bit for bit: every exact CPU path (cpu_double,
// cpu_threads with 1, 2 and 7 threads, the egrid.h C API driven by the golden
// PROTOCOL's steps, a mapping session fed the scans in pieces) on every
// golden case the project carries, compared by
// GRIDMAP payload digest with the map CARMEN 0.7.4 computed (tests/data/golden).
#include <map>

#include "golden_support.h"

namespace vasco {
namespace {

using golden::Case;
using golden::Path;

class GoldenCpu : public ::testing::TestWithParam<std::tuple<Case, int>> {};

TEST_P(GoldenCpu, MatchesCarmen) {
  const Case &c = std::get<0>(GetParam());
  const Path path = golden::exact_cpu_paths().at(std::get<1>(GetParam()));
  golden::expect_golden(c, path);
}

INSTANTIATE_TEST_SUITE_P(
    Carried, GoldenCpu,
    ::testing::Combine(::testing::ValuesIn(golden::carried_cases()),
                       ::testing::Range(0, static_cast<int>(golden::exact_cpu_paths().size()))),
    [](const ::testing::TestParamInfo<std::tuple<Case, int>> &info) {
      std::string p = golden::exact_cpu_paths().at(std::get<1>(info.param)).name;
      for (char &ch : p)
        if (ch == '/') ch = '_';
      return golden::case_label(std::get<0>(info.param)) + "__" + p;
    });

// The cases carried are the ones the issue asks for (fr079 x 4 parameter
// sets, intel x 3, the edge cases x 2), so that a lost line of SHA256SUMS
// cannot shrink the suite unnoticed.
TEST(GoldenCpuCases, CarriesFr079IntelAndEdgeCases) {
  std::map<std::string, int> per_log;
  for (const Case &c : golden::carried_cases()) ++per_log[c.log];
  EXPECT_EQ(per_log["fr079-complete.gfs"], 4);
  EXPECT_EQ(per_log["intel.gfs"], 3);
  EXPECT_EQ(per_log["edge_cases"], 2);
}

}  // namespace
}  // namespace vasco
