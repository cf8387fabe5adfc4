// The log2map tool, run as a program: the command line's conventions
// (messages naming the program, usage errors, --help, -q, warnings for
// options that do nothing, --json, --lenient, "-" for standard input and
// output).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "carmen_compat/map_file.h"
#include "vasco_gpu/params.h"
#include "log2map_test_support.h"
#include "map_test_support.h"

namespace {

using namespace log2maptest;

const std::string kTestLogs = std::string(VASCO_TEST_DATA_DIR) + "/logs/";

TEST(Log2MapConventions, EveryMessageNamesTheProgramAndABadParameterValueIsAUsageError) {
  TempDir dir;
  const ToolRun none = log2map({});
  EXPECT_EQ(none.status, 2);
  EXPECT_EQ(none.output.rfind("log2map: ", 0), 0u) << none.output;
  const ToolRun bad = log2map({kIntel, dir.file("a.map"), "--vasco_range_max", "abc"});
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_TRUE(contains(bad.output, "log2map: command line: vasco_range_max: 'abc' is not a number")) << bad.output;
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Log2MapConventions, ShortQuietFlagAndHelpShowsEachParametersMeaningAndDefault) {
  TempDir dir;
  const ToolRun q = log2map({"-q", "--backend", "cpu_threads", kIntel, dir.file("a.map")});
  EXPECT_EQ(q.status, 0) << q.output;
  EXPECT_EQ(q.output, "");
  const ToolRun help = log2map({"--help"});
  // The help is the parameters' reference (the README points to it): every
  // key, and two rows written out here by hand.
  EXPECT_TRUE(contains(help.output, "--vasco_p_occ VALUE         evidence of a hit (default 0.55; must be strictly between 0 and 1)"))
      << help.output;
  EXPECT_TRUE(contains(help.output, "number of laser messages used (default -1, all; must be >= 1 (or -1 for all))"))
      << help.output;
  for (const std::string &key : vasco::mapper_param_keys())
    EXPECT_TRUE(contains(help.output, "--" + key + " VALUE")) << key;
}

TEST(Log2MapConventions, OptionsThatDoNothingForTheBackendAreWarnedAboutAndInTheJson) {
  TempDir dir;
  const ToolRun r = log2map({"--json", "-q", "--backend", "cpu_double", "--cuda-mode", "exact", "--threads", "2",
                             "--robot", "r2", kIntel, dir.file("a.map")});
  EXPECT_EQ(r.status, 0) << r.output;
  for (const char *w : {"log2map: warning: --cuda-mode does nothing with --backend cpu_double",
                        "log2map: warning: --threads does nothing with --backend cpu_double",
                        "log2map: warning: --robot does nothing without --param-file"})
    EXPECT_TRUE(contains(r.output, w)) << w << "\n" << r.output;
  EXPECT_TRUE(contains(r.output, "\"warnings\":[\"--cuda-mode does nothing")) << r.output;
  // The effective parameters: the defaults here, one overridden.
  const ToolRun o = log2map({"--json", "-q", "--backend", "cpu_double", "--vasco_downsample", "2", kIntel,
                             dir.file("b.map")}, false);
  EXPECT_TRUE(contains(o.output, "\"parameters\":{\"vasco_resolution\":0.025,")) << o.output;
  EXPECT_TRUE(contains(o.output, "\"vasco_downsample\":2,")) << o.output;
}

TEST(Log2MapConventions, JsonAfterAFailureIsStillOneObjectWithTheError) {
  TempDir dir;
  const ToolRun r = log2map({"--json", kTestLogs + "truncated.log.gz", dir.file("a.map")}, false);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.output, "{\"error\":{\"file\":\"" + kTestLogs +
                          "truncated.log.gz\",\"line\":264,\"message\":\"truncated gzip stream: the compressed data "
                          "ends after 26312 uncompressed bytes, before the end of the stream\",\"kind\":\"bad input\"}}\n");
}

TEST(Log2MapConventions, LenientSummaryEndsItsLinesAndADamagedFileSaysWhyItStops) {
  TempDir dir;
  const ToolRun ok = log2map({"--lenient", "--backend", "cpu_threads", kTestLogs + "mixed_bad.log", dir.file("a.map")});
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(contains(ok.output, "(first at line 12)\nlog2map: grid ")) << ok.output;
  const ToolRun gz = log2map({"--lenient", kTestLogs + "truncated.log.gz", dir.file("b.map")});
  EXPECT_EQ(gz.status, 1);
  EXPECT_TRUE(contains(gz.output, "truncated gzip stream")) << gz.output;
  EXPECT_TRUE(contains(gz.output, "--lenient skips bad lines, not a damaged file")) << gz.output;
  EXPECT_TRUE(dir.entries() == std::vector<std::string>{"a.map"});
}


// "-": the log from standard input, a CARMEN map to standard output, the same
// bytes in the GRIDMAP as a file written the usual way.
TEST(Log2MapConventions, DashIsStandardInputAndOutput) {
  TempDir dir;
  const std::string piped = dir.file("piped.map");
  ASSERT_EQ(tooltest::run_tool_piped(kIntel, "log2map", {"-q", "--backend", "cpu_threads", "-", "-"}, piped), 0)
      << maptest::read_bytes(piped + ".err");
  ASSERT_EQ(log2map({"-q", "--backend", "cpu_threads", kIntel, dir.file("file.map")}).status, 0);
  const carmen::MapFile a = carmen::read_map_file(piped), b = carmen::read_map_file(dir.file("file.map"));
  ASSERT_TRUE(a.gridmap && b.gridmap);
  EXPECT_EQ(a.gridmap->cells, b.gridmap->cells);
  EXPECT_EQ(log2map({kIntel, "-", "-"}).status, 2);            // standard output twice
  EXPECT_EQ(log2map({"--json", kIntel, "-"}).status, 2);       // --json wants it too
}

// --json is UTF-8 whatever the file names: a byte that is not (a Latin-1
// name) comes out as \u00XX.
TEST(Log2MapConventions, JsonEscapesBytesThatAreNotUtf8) {
  TempDir dir;
  const ToolRun r = log2map({"--json", dir.file("caf\xe9.log"), dir.file("a.map")}, false);
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, "caf\\u00e9.log")) << r.output;
  EXPECT_FALSE(contains(r.output, "caf\xe9")) << r.output;
}

}  // namespace
