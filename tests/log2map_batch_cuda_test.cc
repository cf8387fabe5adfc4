// log2map's batch mode and --device on the GPU, run as a program: exact
// mode's outputs are CARMEN's maps (the golden digests the project
// carries), float mode's the same GRIDMAP as a one-log cuda run (float mode
// is deterministic), a render split across GPUs (--split-devices) writes the
// one GPU's map, and a --device that does not exist is refused naming it. Skips without a usable GPU.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "carmen_compat/map_file.h"
#include "golden_support.h"
#include "map_test_support.h"
#include "tool_support.h"

namespace {

using maptest::TempDir;
using tooltest::contains;
using tooltest::ToolRun;
using vasco::golden::carried_digest;
using vasco::golden::map_file_digest;

ToolRun log2map(const std::vector<std::string> &args) { return tooltest::run_tool("log2map", args, true); }

const std::string kLogs = VASCO_LOGS_DIR;
const std::string kIntel = kLogs + "/intel.gfs.log.gz";
const std::string kFr079 = kLogs + "/fr079-complete.gfs.log.gz";

class Log2MapBatchCuda : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (!vasco::golden::cuda_available(&why)) GTEST_SKIP() << "no usable GPU: " << why;
  }
};

TEST_F(Log2MapBatchCuda, ExactModeWritesCarmensMaps) {
  TempDir dir;
  const ToolRun r = log2map({"--backend", "cuda", "--cuda-mode", "exact", "--device", "0", "--param-file",
                             vasco::golden::carried_dir() + "/params/vasco_default_ds4.ini", "--out-dir",
                             dir.file("maps"), kIntel, kFr079});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "backend cuda_exact")) << r.output;
  EXPECT_EQ(map_file_digest(dir.file("maps/intel.gfs.map.gz")), carried_digest("intel.gfs__vasco_default_ds4"));
  EXPECT_EQ(map_file_digest(dir.file("maps/fr079-complete.gfs.map.gz")),
            carried_digest("fr079-complete.gfs__vasco_default_ds4"));
}

TEST_F(Log2MapBatchCuda, FloatModeGivesEachLogsOneRunMap) {
  TempDir dir;
  const ToolRun batch = log2map({"--backend", "auto", "--out-dir", dir.file("maps"), kIntel, kFr079});
  ASSERT_EQ(batch.status, 0) << batch.output;
  EXPECT_TRUE(contains(batch.output, "backend cuda_float")) << batch.output;  // auto in a batch: the GPU
  for (const std::string stem : {"intel.gfs", "fr079-complete.gfs"}) {
    const ToolRun one = log2map({"--backend", "cuda", "--quiet", kLogs + "/" + stem + ".log.gz", dir.file(stem + ".map.gz")});
    ASSERT_EQ(one.status, 0) << one.output;
    EXPECT_EQ(map_file_digest(dir.file("maps/" + stem + ".map.gz")), map_file_digest(dir.file(stem + ".map.gz"))) << stem;
  }
}

// Several mappers share a batch (one per GPU, two on one GPU with --devices
// 0,0, three per GPU when the batch chooses): each log is mapped whole by one
// of them, so the outputs are those of one mapper, in either mode.
TEST_F(Log2MapBatchCuda, SeveralMappersGiveTheOneMappersMaps) {
  TempDir dir;
  const std::vector<std::string> logs = {kIntel, kFr079, kLogs + "/fr101.carmen.log.gz"};
  for (const char *mode : {"float", "exact"}) {
    const std::string one = dir.file(std::string("one_") + mode), two = dir.file(std::string("two_") + mode);
    std::vector<std::string> a = {"--backend", "cuda", "--cuda-mode", mode, "--device", "0", "--out-dir", one};
    std::vector<std::string> b = {"--backend", "cuda", "--cuda-mode", mode, "--devices", "0,0", "--out-dir", two};
    a.insert(a.end(), logs.begin(), logs.end());
    b.insert(b.end(), logs.begin(), logs.end());
    const ToolRun r1 = log2map(a), r2 = log2map(b);
    ASSERT_EQ(r1.status, 0) << r1.output;
    ASSERT_EQ(r2.status, 0) << r2.output;
    EXPECT_TRUE(contains(r2.output, "on GPU 0, 2 mappers")) << r2.output;
    for (const std::string stem : {"intel.gfs", "fr079-complete.gfs", "fr101.carmen"})
      EXPECT_EQ(map_file_digest(one + "/" + stem + ".map.gz"), map_file_digest(two + "/" + stem + ".map.gz"))
          << mode << " " << stem;
  }
  // The batch's own choice: three mappers on every GPU, the same maps.
  const std::string own = dir.file("own");
  std::vector<std::string> c = {"--backend", "cuda", "--cuda-mode", "exact", "--out-dir", own};
  c.insert(c.end(), logs.begin(), logs.end());
  const ToolRun r3 = log2map(c);
  ASSERT_EQ(r3.status, 0) << r3.output;
  EXPECT_TRUE(contains(r3.output, ", 3 mappers")) << r3.output;
  for (const std::string stem : {"intel.gfs", "fr079-complete.gfs", "fr101.carmen"})
    EXPECT_EQ(map_file_digest(dir.file("one_exact") + "/" + stem + ".map.gz"),
              map_file_digest(own + "/" + stem + ".map.gz"))
        << stem;
}

// Several mappers on one GPU: an input that runs out of memory beside the
// others is mapped again at the end, alone, and reported once if it fails
// again. With --max-memory 1, intel's map runs out (tried twice, reported
// once) and fr079's read already does (reported at once, never deferred).
TEST_F(Log2MapBatchCuda, OutOfMemoryBesideAnotherMapperIsTriedAgainAlone) {
  TempDir dir;
  const ToolRun r = log2map({"--backend", "cuda", "--devices", "0,0", "--max-memory", "1", "--out-dir",
                             dir.file("maps"), kIntel, kFr079});
  EXPECT_EQ(r.status, 1) << r.output;
  size_t failed = 0;
  for (size_t at = r.output.find("FAILED: "); at != std::string::npos; at = r.output.find("FAILED: ", at + 1)) ++failed;
  EXPECT_EQ(failed, 2u) << "each input once, after its second try\n" << r.output;
  EXPECT_TRUE(contains(r.output, "memory")) << r.output;
  EXPECT_TRUE(contains(r.output, "0 of 2 inputs mapped")) << r.output;
}

// One render split in bands (--split-devices 0,0: two bands on GPU 0 where
// there is one): exact mode writes CARMEN's map, float mode one GPU's.
TEST_F(Log2MapBatchCuda, ASplitRenderWritesTheOneGpuMap) {
  TempDir dir;
  const std::string params = vasco::golden::carried_dir() + "/params/vasco_default_ds4.ini";
  const ToolRun exact = log2map({"--backend", "cuda", "--cuda-mode", "exact", "--split-devices", "0,0", "--param-file",
                                 params, "--quiet", kFr079, dir.file("exact.map.gz")});
  ASSERT_EQ(exact.status, 0) << exact.output;
  EXPECT_EQ(map_file_digest(dir.file("exact.map.gz")), carried_digest("fr079-complete.gfs__vasco_default_ds4"));
  const ToolRun one = log2map({"--backend", "cuda", "--quiet", kFr079, dir.file("one.map.gz")});
  const ToolRun split = log2map({"--backend", "cuda", "--split-devices", "0,0,0", "--quiet", kFr079,
                                 dir.file("split.map.gz")});
  ASSERT_EQ(one.status, 0) << one.output;
  ASSERT_EQ(split.status, 0) << split.output;
  EXPECT_EQ(map_file_digest(dir.file("one.map.gz")), map_file_digest(dir.file("split.map.gz")));
}

TEST_F(Log2MapBatchCuda, ADeviceThatDoesNotExistIsRefusedNamingIt) {
  TempDir dir;
  const ToolRun r = log2map({"--backend", "cuda", "--device", "999", kIntel, dir.file("a.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "CUDA device 999 does not exist")) << r.output;
}

}  // namespace
