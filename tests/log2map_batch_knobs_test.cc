// log2map's batch knobs from the environment (VASCO_BATCH_READ_AHEAD,
// VASCO_BATCH_POOL_NICE, VASCO_BATCH_READ_WORST_MB): a value that is not a whole number in the
// knob's range is a usage error (exit 2) naming the variable, its value and
// the range, before anything is written; unset or empty, the default.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "map_test_support.h"
#include "tool_support.h"

namespace {

using maptest::TempDir;
using tooltest::contains;

const std::string kGood = std::string(VASCO_TEST_DATA_DIR) + "/logs/good.log";

// Sets `name` to `value` for one scope (unset when `value` is null), then
// unsets it again.
class EnvSet {
 public:
  EnvSet(const char *name, const char *value) : name_(name) {
    if (value != nullptr) ::setenv(name, value, 1);
    else ::unsetenv(name);
  }
  ~EnvSet() { ::unsetenv(name_); }
  EnvSet(const EnvSet &) = delete;
  EnvSet &operator=(const EnvSet &) = delete;

 private:
  const char *name_;
};

// A batch of one input into `out` (quiet); what log2map said, and its status.
tooltest::ToolRun batch(const TempDir &out) {
  return tooltest::run_tool("log2map", {"-q", "--backend", "cpu_threads", "--out-dir", out.path(), kGood});
}

TEST(Log2MapBatchKnobs, AReadAheadThatIsNotAWholeNumberInRangeIsAUsageError) {
  for (const char *bad : {"garbage", "0", "65", "-1", "8x", " 8", "+8", "99999999999999999999"}) {
    TempDir out;
    const EnvSet env("VASCO_BATCH_READ_AHEAD", bad);
    const tooltest::ToolRun r = batch(out);
    EXPECT_EQ(r.status, 2) << bad << ": " << r.output;
    EXPECT_TRUE(contains(r.output, std::string("VASCO_BATCH_READ_AHEAD=") + bad)) << r.output;
    EXPECT_TRUE(contains(r.output, "from 1 to 64")) << r.output;
    EXPECT_TRUE(out.entries().empty()) << bad << ": " << out.entries().front() << " written";
  }
}

TEST(Log2MapBatchKnobs, APoolNiceThatIsNotAWholeNumberInRangeIsAUsageError) {
  TempDir out;
  const EnvSet env("VASCO_BATCH_POOL_NICE", "nice");
  const tooltest::ToolRun r = batch(out);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "VASCO_BATCH_POOL_NICE=nice: not a whole number from 0 to 19")) << r.output;
}

TEST(Log2MapBatchKnobs, AWorstCaseThatIsNotAWholeNumberOfMiBInRangeIsAUsageError) {
  for (const char *bad : {"1G", "0", "16777217"}) {
    TempDir out;
    const EnvSet env("VASCO_BATCH_READ_WORST_MB", bad);
    const tooltest::ToolRun r = batch(out);
    EXPECT_EQ(r.status, 2) << bad << ": " << r.output;
    EXPECT_TRUE(contains(r.output, std::string("VASCO_BATCH_READ_WORST_MB=") + bad + ": not a whole number from 1 to "
                                                                                     "16777216"))
        << r.output;
    EXPECT_TRUE(out.entries().empty()) << bad << ": " << out.entries().front() << " written";
  }
  TempDir out;
  const EnvSet env("VASCO_BATCH_READ_WORST_MB", "1");  // below the budget: the budget (reads counted at worst, as before)
  const tooltest::ToolRun r = batch(out);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(out.file("good.map.gz")));
}

// VASCO_BATCH_READ_FIRST=1 (batch_bench's floor experiment): every input
// read before the mapper starts, that read a phase of its own in --json.
TEST(Log2MapBatchKnobs, ReadFirstReadsEveryInputBeforeTheMapperStarts) {
  TempDir out;
  const EnvSet env("VASCO_BATCH_READ_FIRST", "1");
  const tooltest::ToolRun r =
      tooltest::run_tool("log2map", {"-q", "--json", "--backend", "cpu_threads", "--out-dir", out.path(), kGood});
  EXPECT_EQ(r.status, 0) << r.output;
  const std::string key = "\"phases\":{\"read_first\":";
  const size_t at = r.output.find(key);
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_GT(std::strtod(r.output.c_str() + at + key.size(), nullptr), 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(out.file("good.map.gz")));
  const EnvSet bad("VASCO_BATCH_READ_FIRST", "yes");
  EXPECT_EQ(batch(out).status, 2);
}

TEST(Log2MapBatchKnobs, UnsetEmptyOrInRangeTheBatchRuns) {
  for (const char *good : {static_cast<const char *>(nullptr), "", "1", "8", "64"}) {
    TempDir out;
    const EnvSet env("VASCO_BATCH_READ_AHEAD", good);
    const tooltest::ToolRun r = batch(out);
    const std::string what = good == nullptr ? "unset" : "'" + std::string(good) + "'";
    EXPECT_EQ(r.status, 0) << what << ": " << r.output;
    EXPECT_TRUE(std::filesystem::exists(out.file("good.map.gz"))) << what;  // the batch's default format
  }
}

}  // namespace
