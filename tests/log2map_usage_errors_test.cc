// log2map's usage errors for inputs and parameters that cannot give a map:
// a map cell that leaves no mapped cell in CARMEN's finish, a ROS bag given
// for a CARMEN log, and --help's one rule for auto.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <string>
#include <vector>

#include "log2map_test_support.h"
#include "map_test_support.h"

namespace {

using namespace log2maptest;

ToolRun quiet_cpu(std::vector<std::string> args) {
  args.insert(args.begin(), {"-q", "--backend", "cpu_threads"});
  return log2map(args);
}

// intel's grid is 2080 x 2572 cells of 0.025 m with its known cells away
// from the grid's corner: whole blocks of 2000 (or 1200, --resolution 30)
// cells from the corner hold none of them, 1000 still do (the log's own
// map, checked by running it, not by a constant of the rule).
TEST(Log2MapUsageErrors, AMapCellThatKeepsNoMappedCellIsAUsageErrorNamingTheMap) {
  TempDir dir;
  for (const std::vector<std::string> &opts :
       {std::vector<std::string>{"--vasco_downsample", "2000"}, std::vector<std::string>{"--resolution", "30"}}) {
    std::vector<std::string> args = opts;
    args.insert(args.end(), {kIntel, dir.file("a.map")});
    const ToolRun r = quiet_cpu(args);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "leaves no mapped cell")) << r.output;
    EXPECT_TRUE(contains(r.output, "2080 x 2572-cell grid")) << r.output;
    EXPECT_TRUE(contains(r.output, "--resolution or --vasco_downsample")) << r.output;
    EXPECT_FALSE(contains(r.output, "no beam updated any cell")) << r.output;
  }
  EXPECT_TRUE(contains(quiet_cpu({"--vasco_downsample", "2000", kIntel, dir.file("a.map")}).output,
                       "a map cell of 50 m (vasco_downsample 2000 x vasco_resolution 0.025 m)"));
  EXPECT_TRUE(contains(quiet_cpu({"--resolution", "30", kIntel, dir.file("a.map")}).output, "a map of 1 x 2 cells"));
  EXPECT_TRUE(dir.entries().empty());
  const ToolRun fits = quiet_cpu({"--vasco_downsample", "1000", kIntel, dir.file("a.map")});
  EXPECT_EQ(fits.status, 0) << fits.output;
}

TEST(Log2MapUsageErrors, ABagNamesBag2map) {
  TempDir dir;
  ASSERT_EQ(::mkdir(dir.file("run").c_str(), 0755), 0);
  maptest::write_bytes(dir.file("run/metadata.yaml"), "rosbag2_bagfile_information:\n");
  for (const std::string &bag : {dir.file("run.bag"), dir.file("run.MCAP"), dir.file("run_0.db3"), dir.file("run")}) {
    const ToolRun r = log2map({bag, dir.file("a.map")});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "is a ROS bag")) << r.output;
    EXPECT_TRUE(contains(r.output, "map it with bag2map (bag2map " + bag + " OUTPUT")) << r.output;
  }
  const ToolRun batch = log2map({"--out-dir", dir.file("maps"), kIntel, dir.file("run.mcap")});
  EXPECT_EQ(batch.status, 2) << batch.output;
  EXPECT_TRUE(contains(batch.output, "bag2map")) << batch.output;
  const ToolRun added = log2map({"--add", dir.file("run.bag"), kIntel, dir.file("a.map")});
  EXPECT_EQ(added.status, 2) << added.output;
}

TEST(Log2MapUsageErrors, HelpGivesAutoOneRule) {
  const ToolRun help = log2map({"--help"});
  const size_t at = help.output.find("auto: ");
  ASSERT_NE(at, std::string::npos) << help.output;
  const std::string line = help.output.substr(at, help.output.find('\n', at) - at);
  EXPECT_EQ(line, "auto: cuda where a GPU is usable and a measured cost model expects it to finish first (in a batch "
                  "its start-up weighs nothing), else cpu_threads");
}

// Every GPU hidden (CUDA_VISIBLE_DEVICES empty) is known without starting
// CUDA: the note gives the cores' time and no GPU time.
TEST(Log2MapUsageErrors, AutoWithoutAUsableGpuGivesNoGpuTime) {
  TempDir dir;
  ASSERT_EQ(::setenv("CUDA_VISIBLE_DEVICES", "", 1), 0);
  const ToolRun r = log2map({"--backend", "auto", kIntel, dir.file("a.map")});
  ::unsetenv("CUDA_VISIBLE_DEVICES");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "--backend auto: ")) << r.output;
  EXPECT_TRUE(contains(r.output, "using cpu_threads")) << r.output;
  EXPECT_FALSE(contains(r.output, "on the GPU")) << r.output;
}

}  // namespace
