// log2map's batch mode (--out-dir DIR LOG...), run as a program: every
// output is CARMEN's map (the golden digests the project carries) and the
// same GRIDMAP as a run of log2map on that log alone; a bad log is reported
// and skipped, its existing outputs untouched; --fail-fast stops; the
// one-log auto backend says what it chose.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
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
const std::string kFr101 = kLogs + "/fr101.carmen.log.gz";

bool exists(const std::string &path) { return std::filesystem::exists(path); }

std::vector<std::string> names_in(const std::string &dir) {
  std::vector<std::string> names;
  for (const auto &e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string read_all(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(Log2MapBatch, EveryOutputIsCarmensMap) {
  ASSERT_FALSE(carried_digest("intel.gfs__vasco_default_ds4").empty());  // throws when the case is missing
  ASSERT_FALSE(carried_digest("fr079-complete.gfs__vasco_default_ds4").empty());
  for (const char *backend : {"cpu_double", "cpu_threads"}) {
    TempDir dir;
    const std::string out = dir.file("maps");
    const ToolRun r = log2map({"--backend", backend, "--param-file", vasco::golden::carried_dir() + "/params/vasco_default_ds4.ini",
                               "--out-dir", out, "--formats", "map.gz,map", kIntel, kFr079});
    ASSERT_EQ(r.status, 0) << r.output;
    for (const char *fmt : {".map.gz", ".map"}) {
      EXPECT_EQ(map_file_digest(out + "/intel.gfs" + fmt), carried_digest("intel.gfs__vasco_default_ds4")) << backend << fmt;
      EXPECT_EQ(map_file_digest(out + "/fr079-complete.gfs" + fmt), carried_digest("fr079-complete.gfs__vasco_default_ds4"))
          << backend << fmt;
    }
    EXPECT_TRUE(contains(r.output, "2 of 2 inputs mapped")) << r.output;
  }
}

TEST(Log2MapBatch, EachOutputIsTheMapOfARunOnThatLogAlone) {
  TempDir dir;
  const std::vector<std::string> logs = {kIntel, kFr079, kFr101};
  const ToolRun batch = log2map({"--backend", "cpu_threads", "--quiet", "--out-dir", dir.file("batch"), "--formats",
                                 "map.gz,pgm,png", kIntel, kFr079, kFr101});
  ASSERT_EQ(batch.status, 0) << batch.output;
  for (const std::string stem : {"intel.gfs", "fr079-complete.gfs", "fr101.carmen"}) {
    const std::string log = kLogs + "/" + stem + ".log.gz";
    const ToolRun one = log2map({"--backend", "cpu_threads", "--quiet", log, dir.file(stem + ".map.gz"),
                                 dir.file(stem + ".pgm"), dir.file(stem + ".png")});
    ASSERT_EQ(one.status, 0) << one.output;
    EXPECT_EQ(map_file_digest(dir.file("batch/" + stem + ".map.gz")), map_file_digest(dir.file(stem + ".map.gz"))) << stem;
    for (const char *ext : {".pgm", ".yaml", ".png"}) {
      const std::string a = read_all(dir.file("batch/" + stem + ext)), b = read_all(dir.file(stem + ext));
      // The YAML names its image: the same name in another directory.
      EXPECT_TRUE(!a.empty() && a == b) << stem << ext;
    }
  }
}

TEST(Log2MapBatch, ABadLogIsReportedAndSkippedItsOutputsUntouched) {
  TempDir dir;
  maptest::write_bytes(dir.file("garbage.log"), "this is not a CARMEN log\n\x01\x02\n");
  const std::string out = dir.file("maps");
  std::filesystem::create_directory(out);
  maptest::write_bytes(out + "/garbage.map.gz", "an older map, kept");
  const ToolRun r = log2map({"--backend", "cpu_threads", "--out-dir", out, dir.file("garbage.log"),
                             dir.file("missing.log"), kIntel});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, dir.file("garbage.log"))) << r.output;
  EXPECT_TRUE(contains(r.output, dir.file("missing.log"))) << r.output;
  EXPECT_TRUE(contains(r.output, "2 of 3 inputs failed")) << r.output;
  EXPECT_TRUE(contains(r.output, "1 of 3 inputs mapped")) << r.output;
  EXPECT_TRUE(exists(out + "/intel.gfs.map.gz"));
  EXPECT_FALSE(exists(out + "/missing.map.gz"));
  EXPECT_EQ(read_all(out + "/garbage.map.gz"), "an older map, kept");
  // No temporary left: only the outputs in the directory.
  EXPECT_EQ(names_in(out), (std::vector<std::string>{"garbage.map.gz", "intel.gfs.map.gz"}));
}

TEST(Log2MapBatch, AFailedBatchLeavesNoDirectoryOfItsOwn) {
  TempDir dir;
  maptest::write_bytes(dir.file("garbage.log"), "PARAM\n");
  // Every input fails: the directory the batch made goes again.
  ToolRun r = log2map({"--backend", "cpu_threads", "--out-dir", dir.file("made"), dir.file("garbage.log"),
                       dir.file("missing.log")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_FALSE(exists(dir.file("made"))) << r.output;
  // A directory that was there stays, empty or not.
  std::filesystem::create_directory(dir.file("there"));
  r = log2map({"--backend", "cpu_threads", "--out-dir", dir.file("there"), dir.file("garbage.log")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(exists(dir.file("there")));
  // One input mapped: the directory holds its map.
  r = log2map({"--backend", "cpu_threads", "-q", "--out-dir", dir.file("some"), dir.file("garbage.log"), kIntel});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_EQ(names_in(dir.file("some")), (std::vector<std::string>{"intel.gfs.map.gz"}));
}

TEST(Log2MapBatch, FailFastStopsAtTheFirstBadLog) {
  TempDir dir;
  maptest::write_bytes(dir.file("garbage.log"), "PARAM\n");
  const ToolRun r = log2map({"--backend", "cpu_threads", "--fail-fast", "--out-dir", dir.file("maps"),
                             dir.file("garbage.log"), kIntel, kFr079});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "not run (--fail-fast)")) << r.output;
  EXPECT_FALSE(exists(dir.file("maps/fr079-complete.gfs.map.gz")));
}

TEST(Log2MapBatch, JsonReportsEveryInput) {
  TempDir dir;
  const ToolRun r = tooltest::run_tool("log2map", {"--backend", "cpu_threads", "--json", "--quiet", "--out-dir",
                                                   dir.file("maps"), kIntel, dir.file("missing.log")},
                                       false);
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "\"state\":\"done\",\"scans\":910")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"state\":\"failed\",\"error\":")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"done\":1,\"failed\":1")) << r.output;
  // The stages batch_bench reads: the mapper's wait beside read, map and write, and the threads.
  EXPECT_TRUE(contains(r.output, ",\"mapper_wait\":")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"mappers\":1,")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"pool_threads\":")) << r.output;
  // The phases: no read before the mappers (VASCO_BATCH_READ_FIRST unset), the start-up, then the
  // mapping, which holds the one input's map, then the last writes.
  const auto number_after = [&](const std::string &key) {
    const size_t at = r.output.find(key);
    return at == std::string::npos ? -1.0 : std::strtod(r.output.c_str() + at + key.size(), nullptr);
  };
  EXPECT_EQ(number_after("\"phases\":{\"read_first\":"), 0) << r.output;
  const double start = number_after(",\"start\":"), mapping = number_after(",\"mapping\":"),
               drain = number_after(",\"drain\":"), map = number_after(",\"map\":");
  EXPECT_GT(start, 0) << r.output;
  EXPECT_GT(map, 0) << r.output;
  EXPECT_GE(mapping, map) << r.output;
  EXPECT_GE(drain, 0) << r.output;
  EXPECT_LE(start + mapping + drain, number_after("\"failed\":1,\"seconds\":") + 1e-6) << r.output;
}

TEST(Log2MapBatch, UsageErrorsBeforeAnyWork) {
  TempDir dir;
  const std::string out = dir.file("maps");
  std::filesystem::create_directory(dir.file("b"));
  std::filesystem::copy_file(kIntel, dir.file("b/intel.gfs.log.gz"));
  const std::vector<std::vector<std::string>> bad = {
      {"--out-dir", out, kIntel, dir.file("b/intel.gfs.log.gz")},  // the same outputs twice
      {"--out-dir", out, "--formats", "map.gz,jpg", kIntel},
      {"--out-dir", out, "--formats", "png,png", kIntel},
      {"--formats", "png", kIntel, dir.file("x.map")},  // --formats without --out-dir
      {"--out-dir", out, "--poses", kIntel, kIntel},
      {kIntel},  // no output
  };
  for (const auto &args : bad) {
    const ToolRun r = log2map(args);
    EXPECT_EQ(r.status, 2) << args.back() << "\n" << r.output;
  }
  EXPECT_FALSE(exists(out));
  const ToolRun same = log2map({"--out-dir", out, kIntel, dir.file("b/intel.gfs.log.gz")});
  EXPECT_TRUE(contains(same.output, "would both write")) << same.output;
  maptest::write_bytes(dir.file("file"), "x");
  const ToolRun not_dir = log2map({"--out-dir", dir.file("file"), kIntel});
  EXPECT_EQ(not_dir.status, 1) << not_dir.output;
  EXPECT_TRUE(contains(not_dir.output, "not a directory")) << not_dir.output;
}

TEST(Log2MapAuto, OneLogSaysWhatItChoseAndWhy) {
  TempDir dir;
  const ToolRun r = log2map({"--backend", "auto", kIntel, dir.file("a.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "--backend auto: ")) << r.output;
  EXPECT_TRUE(contains(r.output, "cell updates: about")) << r.output;
  const ToolRun quiet = log2map({"--backend", "auto", "--quiet", kIntel, dir.file("b.map")});
  ASSERT_EQ(quiet.status, 0) << quiet.output;
  EXPECT_EQ(quiet.output, "");
  EXPECT_EQ(map_file_digest(dir.file("a.map")), map_file_digest(dir.file("b.map")));
}

}  // namespace
