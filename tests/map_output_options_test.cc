// The map-output rows (map_output_options.h) against what they describe,
// each by another route: the defaults against carmen_compat's
// MapServerOptions and against the YAML log2map writes with no flag given,
// every choice against the parsers and the command line, the bounds against
// refusals naming the flag, map_mode's alias, and the batch's default
// formats against the files a batch writes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include "carmen_compat/error.h"
#include "carmen_compat/image_io.h"
#include "carmen_compat/map_format.h"
#include "map_test_support.h"
#include "tool_support.h"
#include "vasco_gpu/pipeline/map_output_options.h"
#include "vasco_gpu/pipeline/outputs.h"

namespace {

using tooltest::contains;
using tooltest::ToolRun;
using vasco::OptionSpec;
using vasco::OptionType;
namespace pl = vasco::pipeline;

const std::string kIntel = std::string(VASCO_LOGS_DIR) + "/intel.gfs.log.gz";

ToolRun log2map(const std::vector<std::string> &args) { return tooltest::run_tool("log2map", args, true); }

const OptionSpec &row(const char *name) { return vasco::option_row(pl::map_output_option_table(), name); }

double number(const std::string &text) { return std::strtod(text.c_str(), nullptr); }

// The value of `key` in a map_server YAML ("key: value" lines).
std::string yaml_value(const std::string &yaml, const std::string &key) {
  const size_t at = yaml.find("\n" + key + ": ");
  if (at == std::string::npos) return std::string();
  const size_t from = at + key.size() + 3;
  return yaml.substr(from, yaml.find('\n', from) - from);
}

TEST(MapOutputOptions, EveryRowIsInLog2mapsHelp) {
  const ToolRun help = log2map({"--help"});
  ASSERT_EQ(help.status, 0);
  for (const OptionSpec &r : pl::map_output_option_table()) {
    EXPECT_FALSE(r.help.empty()) << r.name;
    if (r.name == "map_mode") continue;  // the ROS node's and Python's: OccupancyGrid data
    EXPECT_TRUE(contains(help.output, r.flag())) << r.flag();
    EXPECT_TRUE(contains(help.output, r.type == OptionType::Flag ? r.help : r.help_with_default())) << r.name;
  }
  for (const std::string &n : pl::map_server_option_names()) EXPECT_NE(vasco::find_option(pl::map_output_option_table(), n), nullptr);
}

TEST(MapOutputOptions, DefaultsAreCarmenCompats) {
  const carmen::MapServerOptions d;
  EXPECT_EQ(row("mode").default_text, carmen::pgm_mode_name(d.mode));
  EXPECT_EQ(number(row("free_thresh").default_text), d.free_thresh);
  EXPECT_EQ(number(row("occupied_thresh").default_text), d.occupied_thresh);
  EXPECT_EQ(row("negate").default_text, d.negate ? "true" : "false");
  EXPECT_EQ(number(row("free_thresh").default_text), carmen::kFreeThresh);
  EXPECT_EQ(row("map_mode").default_text, "trinary");
}

// log2map with no map_server flag writes the rows' defaults into the YAML.
TEST(MapOutputOptions, TheCommandLineWritesTheDefaultsWithoutAFlag) {
  maptest::TempDir dir;
  const ToolRun r = log2map({"--vasco_num_scans", "20", kIntel, dir.file("m.pgm")});
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string yaml = "\n" + maptest::read_bytes(dir.file("m.yaml"));
  EXPECT_EQ(number(yaml_value(yaml, "free_thresh")), number(row("free_thresh").default_text)) << yaml;
  EXPECT_EQ(number(yaml_value(yaml, "occupied_thresh")), number(row("occupied_thresh").default_text)) << yaml;
  EXPECT_EQ(yaml_value(yaml, "negate"), "0") << yaml;
  const std::string mode = yaml_value(yaml, "mode");
  EXPECT_TRUE(mode.empty() || mode == row("mode").default_text) << yaml;
}

TEST(MapOutputOptions, EveryModeIsAccepted) {
  maptest::TempDir dir;
  for (const std::string &c : row("mode").choices) {
    carmen::PgmMode m;
    EXPECT_TRUE(carmen::parse_pgm_mode(c, &m)) << c;
    const ToolRun r = log2map({"--vasco_num_scans", "20", "--mode", c, kIntel, dir.file(c + ".pgm")});
    EXPECT_EQ(r.status, 0) << r.output;
  }
  const ToolRun bad = log2map({"--mode", "fancy", kIntel, dir.file("x.pgm")});
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(contains(bad.output, "--mode")) << bad.output;
}

TEST(MapOutputOptions, AThresholdOutOfBoundsIsRefusedNamingTheFlag) {
  for (const char *n : {"free_thresh", "occupied_thresh"}) {
    const OptionSpec &r = row(n);
    EXPECT_FALSE(r.in_bounds(1.5)) << n;
    EXPECT_FALSE(r.in_bounds(-0.1)) << n;
    const ToolRun run = log2map({r.flag(), "1.5", kIntel, "x.pgm"});
    EXPECT_EQ(run.status, 2);
    EXPECT_TRUE(contains(run.output, r.flag())) << run.output;
    try {
      pl::checked_map_server_options("trinary", r.name == "free_thresh" ? 1.5 : 0.196,
                                     r.name == "free_thresh" ? 0.65 : 1.5, false, pl::OptionNaming::Keyword);
      ADD_FAILURE() << n;
    } catch (const carmen::Error &e) {
      EXPECT_EQ(e.code(), carmen::ErrorCode::Usage);
      EXPECT_TRUE(contains(e.what(), r.name + " 1.5")) << e.what();
    }
  }
  // The pair's own rule (free below occupied) names both, as the front end spells them.
  EXPECT_THROW(pl::checked_map_server_options("trinary", 0.7, 0.65, false, pl::OptionNaming::Flag), carmen::Error);
  EXPECT_THROW(pl::checked_map_server_options("raw", 0.196, 0.65, true, pl::OptionNaming::Flag), carmen::Error);
  const carmen::MapServerOptions d;
  const carmen::MapServerOptions o = pl::checked_map_server_options(
      row("mode").default_text, number(row("free_thresh").default_text), number(row("occupied_thresh").default_text),
      false, pl::OptionNaming::Flag);
  EXPECT_EQ(o.mode, d.mode);
  EXPECT_EQ(o.free_thresh, d.free_thresh);
  EXPECT_EQ(o.occupied_thresh, d.occupied_thresh);
}

TEST(MapOutputOptions, MapModeTakesItsChoicesAndTheAlias) {
  EXPECT_EQ(pl::occupancy_data_mode("trinary", pl::OptionNaming::Keyword), carmen::PgmMode::Trinary);
  EXPECT_EQ(pl::occupancy_data_mode("scale", pl::OptionNaming::Keyword), carmen::PgmMode::Raw);
  for (const pl::ChoiceAlias &a : pl::map_mode_aliases()) {
    const auto &choices = row("map_mode").choices;
    EXPECT_NE(std::find(choices.begin(), choices.end(), a.choice), choices.end()) << a.alias;
    EXPECT_EQ(pl::occupancy_data_mode(a.alias, pl::OptionNaming::Keyword),
              pl::occupancy_data_mode(a.choice, pl::OptionNaming::Keyword));
  }
  try {
    pl::occupancy_data_mode("fancy", pl::OptionNaming::Keyword);
    ADD_FAILURE();
  } catch (const carmen::Error &e) {
    EXPECT_EQ(e.code(), carmen::ErrorCode::Usage);
    EXPECT_TRUE(contains(e.what(), "map_mode 'fancy'")) << e.what();
  }
}

TEST(MapOutputOptions, FormatsAreTheFormatTablesAndTheDefaultIsWhatABatchWrites) {
  const OptionSpec &f = row("formats");
  EXPECT_EQ(f.choices, carmen::map_format_names());
  for (const std::string &c : f.choices) EXPECT_NO_THROW(pl::check_map_formats({c}, "formats")) << c;
  maptest::TempDir dir;
  maptest::write_bytes(dir.file("in.log"), maptest::gunzip_file(kIntel));
  const ToolRun r = log2map({"--vasco_num_scans", "20", "--out-dir", dir.file("out"), dir.file("in.log")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(maptest::file_exists(dir.file("out/in." + f.default_text))) << r.output;
}

}  // namespace
