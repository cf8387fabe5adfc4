// The pipeline's outputs (vasco_gpu/pipeline/outputs.h, mapped.h): names,
// formats, plans and checks every front end shares. Expected values are
// written out by hand from the rules in the header.
#include "vasco_gpu/pipeline/outputs.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "carmen_compat/error.h"
#include "temp_dir.h"
#include "vasco_gpu/pipeline/log_scans.h"
#include "vasco_gpu/pipeline/mapped.h"

namespace {

using vasco::pipeline::check_map_formats;
using vasco::pipeline::check_outputs;
using vasco::pipeline::output_stem;
using vasco::pipeline::plan_outputs;

// The message of the carmen::Error `fn` throws with code Usage ("" if none).
template <class Fn>
std::string usage_error(Fn fn) {
  try {
    fn();
  } catch (const carmen::Error &e) {
    EXPECT_EQ(e.code(), carmen::ErrorCode::Usage) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error";
  return "";
}

TEST(PipelineOutputs, StemDropsGzThenOneExtension) {
  EXPECT_EQ(output_stem("logs/fr079-complete.gfs.log.gz"), "fr079-complete.gfs");
  EXPECT_EQ(output_stem("run.mcap"), "run");
  EXPECT_EQ(output_stem("bags/run_2/"), "run_2");  // a ROS 2 bag's directory
  EXPECT_EQ(output_stem("x.gz"), "x");
  EXPECT_EQ(output_stem(".hidden"), ".hidden");  // a leading dot is the name, not an extension
  EXPECT_EQ(output_stem("plain"), "plain");
}

TEST(PipelineOutputs, FormatsAreTheTableNames) {
  EXPECT_EQ(check_map_formats({"map.gz", "png"}, "f"), (std::vector<std::string>{"map.gz", "png"}));
  EXPECT_EQ(check_map_formats({"png+yaml"}, "f"), std::vector<std::string>{"png+yaml"});
  EXPECT_NE(usage_error([] { check_map_formats({"jpg"}, "--formats 'jpg'"); }).find("--formats 'jpg': 'jpg' is none of map, map.gz"),
            std::string::npos);
  EXPECT_NE(usage_error([] { check_map_formats({"png", "png"}, "f"); }).find("png is named twice"), std::string::npos);
  EXPECT_NE(usage_error([] { check_map_formats({}, "f"); }).find("at least one"), std::string::npos);
  // pgm writes STEM.pgm + STEM.yaml, yaml writes STEM.yaml + STEM.pgm.
  EXPECT_NE(usage_error([] { check_map_formats({"pgm", "yaml"}, "f"); }).find("pgm and yaml both write STEM."),
            std::string::npos);
}

TEST(PipelineOutputs, PlanNamesEachOutputAndRefusesTwoInputsOfOneStem) {
  const auto plan = plan_outputs({"a/x.log.gz", "b/y.clf"}, "out", {"map", "pgm"});
  ASSERT_EQ(plan.size(), 2u);
  EXPECT_EQ(plan[0].input, "a/x.log.gz");
  EXPECT_EQ(plan[0].outputs, (std::vector<std::string>{"out/x.map", "out/x.pgm"}));
  EXPECT_EQ(plan[1].outputs, (std::vector<std::string>{"out/y.map", "out/y.pgm"}));
  EXPECT_EQ(plan_outputs({"x.log"}, "out/", {"png"})[0].outputs, std::vector<std::string>{"out/x.png"});
  const std::string e = usage_error([] { plan_outputs({"a/x.log", "b/x.log.gz"}, "out", {"map"}, "map_logs: "); });
  EXPECT_EQ(e.rfind("map_logs: a/x.log and b/x.log.gz would both write out/x.*", 0), 0u) << e;
}

TEST(PipelineOutputs, AnOutputMustNotBeAnInputOrAnotherOutput) {
  TempDir dir;
  const std::string log = dir.file("x.map");
  std::ofstream(log) << "not a map\n";
  EXPECT_NE(usage_error([&] { check_outputs({log}, {log}); }).find("an output must not overwrite what is read"),
            std::string::npos);
  const std::string out = dir.file("y.map");
  EXPECT_NE(usage_error([&] { check_outputs({}, {out, out}); }).find("give each output once"), std::string::npos);
  EXPECT_NO_THROW(check_outputs({log}, {out}));
}

TEST(PipelineOutputs, SameTargetsAreFoundThroughOtherNamesToo) {
  TempDir dir;
  const std::string log = dir.file("x.map");
  std::ofstream(log) << "not a map\n";
  ASSERT_EQ(::symlink(log.c_str(), dir.file("link.map").c_str()), 0);
  ASSERT_EQ(::link(log.c_str(), dir.file("hard.map").c_str()), 0);
  const std::string dotted = dir.file(".") + "/y.map";
  // an existing file under another name (symlink, hard link); one place spelt two ways
  EXPECT_NE(usage_error([&] { check_outputs({dir.file("link.map")}, {dir.file("hard.map")}); })
                .find("is the input " + dir.file("link.map")),
            std::string::npos);
  EXPECT_NE(usage_error([&] { check_outputs({}, {dir.file("y.map"), dir.file("z.map"), dotted}); })
                .find("the same file as the output " + dir.file("y.map")),
            std::string::npos);
}

TEST(PipelineOutputs, ThousandsOfOutputsAreCheckedInOnePass) {
  // 20,000 existing outputs: the pair-by-pair check made 4e8 stat calls
  // (minutes); one look at each path takes well under a second. The bound is
  // for that difference, not a speed claim.
  TempDir dir;
  std::vector<std::string> outs;
  for (int i = 0; i < 20000; ++i) {
    outs.push_back(dir.file("m" + std::to_string(i) + ".map"));
    std::ofstream(outs.back()) << "x";
  }
  const auto start = std::chrono::steady_clock::now();
  EXPECT_NO_THROW(check_outputs({dir.file("in.log")}, outs));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30.0);
}

TEST(PipelineOutputs, OutputFilesNameEveryFileOfAPair) {
  EXPECT_EQ(vasco::pipeline::output_files({"m.pgm", "m.map.gz"}),
            (std::vector<std::string>{"m.pgm", "m.yaml", "m.map.gz"}));
}

TEST(PipelineMapped, AMapWithoutAKnownCellIsRefusedSayingWhy) {
  vasco::ScanBatch far;
  const float ranges[2] = {60.0f, 80.0f};  // both at or past CARMEN's 50 m: no beam used
  far.add_scan(0, 0, 0, 0, 0.01, ranges, 2, 7);
  EXPECT_EQ(vasco::pipeline::known_cells({-1.0f, 0.5f, -1.0f}), 1u);
  try {
    vasco::pipeline::check_mapped({-1.0f, -1.0f}, far, "far.log");
    ADD_FAILURE() << "no error";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), "far.log");
    EXPECT_NE(std::string(e.what()).find("every one of the 2 ranges of the 1 scans"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(vasco::pipeline::check_mapped({-1.0f, 0.0f}, far, "far.log"));
}

TEST(ScanMessages, TheFrontLaserWithAPoseIsWhatIsMapped) {
  EXPECT_TRUE(vasco::is_scan_message(carmen::MessageType::FLASER));
  EXPECT_TRUE(vasco::is_scan_message(carmen::MessageType::ROBOTLASER1));
  for (carmen::MessageType t : {carmen::MessageType::RLASER, carmen::MessageType::ROBOTLASER2,
                                carmen::MessageType::RAWLASER1, carmen::MessageType::ODOM, carmen::MessageType::PARAM})
    EXPECT_FALSE(vasco::is_scan_message(t)) << carmen::message_type_name(t);
  EXPECT_EQ(vasco::scan_message_names(), "FLASER or ROBOTLASER1");
  EXPECT_EQ(vasco::scan_message_bits(), carmen::message_type_bit(carmen::MessageType::FLASER) |
                                            carmen::message_type_bit(carmen::MessageType::ROBOTLASER1));
}

}  // namespace
