// The pose-source rows (pose_source_options.h) against what they describe,
// each by another route: the defaults against PoseSource's members and
// against log2map's own messages with no flag given, every choice against
// the parsers the pipeline runs and the command line, every bound against a
// refusal naming the flag, and the rule "pose options go with poses" for
// each row.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "carmen_compat/error.h"
#include "map_test_support.h"
#include "tool_support.h"
#include "vasco_gpu/pipeline/log_input.h"
#include "vasco_gpu/pipeline/pose_match.h"
#include "vasco_gpu/pipeline/pose_source_options.h"

namespace {

using tooltest::contains;
using tooltest::ToolRun;
using vasco::OptionSpec;
using vasco::OptionType;
namespace pl = vasco::pipeline;

const std::string kIntel = std::string(VASCO_LOGS_DIR) + "/intel.gfs.log.gz";

ToolRun log2map(const std::vector<std::string> &args) { return tooltest::run_tool("log2map", args, true); }

const OptionSpec &row(const char *name) { return vasco::option_row(pl::pose_source_option_table(), name); }

double number(const std::string &text) { return std::strtod(text.c_str(), nullptr); }

// The first scan's stamp in the intel log.
double first_stamp() {
  std::istringstream in(maptest::gunzip_file(kIntel));
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("FLASER ", 0) != 0) continue;
    std::istringstream ls(line);
    std::vector<std::string> tok;
    for (std::string t; ls >> t;) tok.push_back(t);
    return std::stod(tok[2 + std::stoul(tok[1]) + 6]);  // after the ranges: x y theta odom x y theta, then ipc stamp
  }
  return NAN;
}

TEST(PoseSourceOptions, EveryRowIsAFlagAndAKeyword) {
  const std::vector<std::string> names = {"poses",          "pose_format",  "pose_match", "pose_ids", "pose_max_gap",
                                          "pose_tolerance", "skip_unposed", "pose_frame", "laser_mount"};
  ASSERT_EQ(pl::pose_source_option_table().size(), names.size());
  const ToolRun help = log2map({"--help"});
  ASSERT_EQ(help.status, 0);
  for (const std::string &n : names) {
    const OptionSpec &r = row(n.c_str());
    EXPECT_FALSE(r.help.empty()) << n;
    EXPECT_TRUE(contains(help.output, r.flag())) << r.flag();
    if (r.type == OptionType::Choice) {
      EXPECT_FALSE(r.choices.empty()) << n;
      for (const std::string &c : r.choices) EXPECT_TRUE(contains(r.help, c)) << n << ": " << c;
    }
  }
}

TEST(PoseSourceOptions, DefaultsArePoseSources) {
  const vasco::PoseSource d;
  EXPECT_EQ(vasco::pose_file_format_from_name(row("pose_format").default_text), d.format);
  EXPECT_EQ(vasco::pose_matching_from_name(row("pose_match").default_text), d.match.matching);
  EXPECT_EQ(number(row("pose_max_gap").default_text), d.match.max_gap);
  EXPECT_EQ(number(row("pose_tolerance").default_text), d.match.tolerance);
  EXPECT_EQ(row("skip_unposed").default_text, d.match.skip_unmatched ? "true" : "false");
  EXPECT_EQ(row("pose_frame").default_text, d.robot_frame ? "robot" : "laser");
  for (const char *n : {"pose_format", "pose_match", "pose_frame"}) {
    const OptionSpec &r = row(n);
    EXPECT_NE(std::find(r.choices.begin(), r.choices.end(), r.default_text), r.choices.end()) << n;
  }
}

// Two poses 6 s apart around the first scan, 3 s from it: the gap is over
// the default limit and the nearer pose past the default tolerance, and the
// message says both limits as log2map took them without a flag.
TEST(PoseSourceOptions, TheCommandLineTakesTheDefaultsWithoutAFlag) {
  maptest::TempDir dir;
  const double t = first_stamp();
  ASSERT_TRUE(std::isfinite(t));
  char tum[200];
  std::snprintf(tum, sizeof tum, "%.17g 0 0 0 0 0 0 1\n%.17g 1 0 0 0 0 0 1\n", t - 3, t + 3);
  maptest::write_bytes(dir.file("p.txt"), tum);
  const ToolRun r = log2map({"--poses", dir.file("p.txt"), kIntel, dir.file("x.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "more than --pose-max-gap " + row("pose_max_gap").default_text)) << r.output;
  EXPECT_TRUE(contains(r.output, "more than --pose-tolerance " + row("pose_tolerance").default_text)) << r.output;
}

TEST(PoseSourceOptions, EveryChoiceIsAccepted) {
  for (const std::string &c : row("pose_format").choices) EXPECT_NO_THROW(vasco::pose_file_format_from_name(c)) << c;
  for (const std::string &c : row("pose_match").choices) EXPECT_NO_THROW(vasco::pose_matching_from_name(c)) << c;
  // On the command line: a choice passes the parse, and only the rule
  // (no --poses) refuses it; a value that is no choice is refused first.
  for (const char *n : {"pose_format", "pose_match", "pose_frame"}) {
    const OptionSpec &r = row(n);
    for (const std::string &c : r.choices) {
      const ToolRun run = log2map({r.flag(), c, kIntel, "x.map"});
      EXPECT_EQ(run.status, 2);
      EXPECT_TRUE(contains(run.output, "go with --poses FILE")) << run.output;
    }
    const ToolRun bad = log2map({r.flag(), "sideways", kIntel, "x.map"});
    EXPECT_EQ(bad.status, 2);
    EXPECT_TRUE(contains(bad.output, r.flag())) << bad.output;
    EXPECT_FALSE(contains(bad.output, "go with --poses FILE")) << bad.output;
  }
}

TEST(PoseSourceOptions, AValueOutOfBoundsIsRefusedNamingTheFlag) {
  for (const char *n : {"pose_max_gap", "pose_tolerance"}) {
    const OptionSpec &r = row(n);
    EXPECT_FALSE(r.in_bounds(-1)) << n;
    EXPECT_TRUE(r.in_bounds(number(r.default_text))) << n;
    const ToolRun run = log2map({"--poses", "p.txt", r.flag(), "-1", kIntel, "x.map"});
    EXPECT_EQ(run.status, 2);
    EXPECT_TRUE(contains(run.output, r.flag())) << run.output;
  }
  // Any gap may be bridged (inf); the tolerance is finite.
  EXPECT_TRUE(row("pose_max_gap").in_bounds(INFINITY));
  EXPECT_FALSE(row("pose_tolerance").in_bounds(INFINITY));
  const ToolRun inf = log2map({"--poses", "p.txt", "--pose-tolerance", "inf", kIntel, "x.map"});
  EXPECT_EQ(inf.status, 2);
  EXPECT_TRUE(contains(inf.output, "--pose-tolerance")) << inf.output;
}

TEST(PoseSourceOptions, EveryPoseOptionGoesWithPoses) {
  for (const OptionSpec &r : pl::pose_source_option_table()) {
    if (r.name == "poses") continue;
    try {
      pl::check_pose_options_given({r.name}, false, pl::OptionNaming::Keyword);
      ADD_FAILURE() << r.name << " taken without poses";
    } catch (const carmen::Error &e) {
      EXPECT_EQ(e.code(), carmen::ErrorCode::Usage);
      EXPECT_TRUE(contains(e.what(), r.name + ": ")) << e.what();
      EXPECT_TRUE(contains(e.what(), "poses=FILE")) << e.what();
    }
    EXPECT_NO_THROW(pl::check_pose_options_given({"poses", r.name}, false, pl::OptionNaming::Flag));
    // log2map: the flag alone is refused, naming it.
    std::vector<std::string> args = {r.flag()};
    if (r.type != OptionType::Flag) args.push_back(r.type == OptionType::Choice ? r.choices.back() : "1,2,3");
    if (r.name == "pose_max_gap" || r.name == "pose_tolerance") args.back() = "1";
    args.insert(args.end(), {kIntel, "x.map"});
    const ToolRun run = log2map(args);
    EXPECT_EQ(run.status, 2) << r.name;
    EXPECT_TRUE(contains(run.output, r.flag() + ": the pose options")) << run.output;
  }
  // A bag's reader poses its own scans: the mount and skip_unposed need no file there.
  EXPECT_NO_THROW(pl::check_pose_options_given({"laser_mount", "skip_unposed"}, true, pl::OptionNaming::Keyword));
  EXPECT_THROW(pl::check_pose_options_given({"pose_match"}, true, pl::OptionNaming::Keyword), carmen::Error);
}

TEST(PoseSourceOptions, CarmenLogExtensionsAreWhatAutoReadsAsALog) {
  maptest::TempDir dir;
  const std::string log = maptest::gunzip_file(kIntel);
  for (const std::string &ext : pl::carmen_log_extensions()) {
    maptest::write_bytes(dir.file("poses" + ext), log);
    EXPECT_EQ(vasco::read_pose_file(dir.file("poses" + ext)).format, vasco::PoseFileFormat::CarmenLog) << ext;
  }
  EXPECT_EQ(pl::carmen_log_extensions_text("/"), ".log/.clf");
}

}  // namespace
