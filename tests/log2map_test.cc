// The log2map tool, run as a program: outputs, exit codes, messages. Signals:
// log2map_signals_test.cc; the output transaction: log2map_outputs_test.cc;
// the command line's conventions: log2map_conventions_test.cc.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "carmen_compat/map_file.h"
#include "vasco_gpu/params.h"
#include "log2map_test_support.h"
#include "map_test_support.h"
#include "test_support.h"

namespace {

using namespace log2maptest;

TEST(Log2Map, VersionNamesTheBackends) {
  const ToolRun r = log2map({"--version"});
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(contains(r.output, "cpu_double")) << r.output;
  EXPECT_TRUE(contains(r.output, "cpu_float")) << r.output;
}

TEST(Log2Map, UsageErrorsExitTwo) {
  TempDir dir;
  EXPECT_EQ(log2map({}).status, 2);
  EXPECT_EQ(log2map({kIntel}).status, 2);
  EXPECT_EQ(log2map({"--no-such-flag", kIntel, dir.file("a.map")}).status, 2);
  EXPECT_EQ(log2map({"--backend", "gpu9000", kIntel, dir.file("a.map")}).status, 2);
  // --split-devices: GPU numbers, one render (not a batch), not with --device.
  const ToolRun split = log2map({"--split-devices", "0,x", kIntel, dir.file("a.map")});
  EXPECT_EQ(split.status, 2);
  EXPECT_TRUE(contains(split.output, "--split-devices '0,x'")) << split.output;
  EXPECT_EQ(log2map({"--split-devices", "0,1", "--out-dir", dir.file("maps"), kIntel}).status, 2);
  EXPECT_EQ(log2map({"--split-devices", "0,1", "--device", "0", kIntel, dir.file("a.map")}).status, 2);
  const ToolRun ext = log2map({kIntel, dir.file("a.jpeg")});
  EXPECT_EQ(ext.status, 2);
  EXPECT_TRUE(contains(ext.output, "a.jpeg")) << ext.output;
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Log2Map, WritesEveryFormatAndTheMapIsTheOraclesFinishedGrid) {
  TempDir dir;
  const ToolRun r = log2map({"--backend", "cpu_double", "--json", kIntel, dir.file("m.map.gz"),
                             dir.file("m.pgm"), dir.file("m.png"), dir.file("plain.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"m.map.gz", "m.pgm", "m.png", "m.yaml", "plain.map"}));
  EXPECT_TRUE(contains(r.output, "\"cell_updates\":")) << r.output;
  EXPECT_TRUE(contains(r.output, "910 scans")) << r.output;

  // The GRIDMAP equals finish(cpu_double) computed here, in process.
  const vasco::MapperParams params;
  const auto log = vasco::testing_support::load_log(kIntel, params);
  const auto cells = vasco::render_grid(*vasco::make_renderer("cpu_double"), log.batch, params, log.geo);
  const auto fin = vasco::finish_grid(cells.data(), log.geo.size_x, log.geo.size_y, log.geo.resolution,
                                      4, 20);
  for (const char *name : {"m.map.gz", "plain.map"}) {
    const carmen::MapFile mf = carmen::read_map_file(dir.file(name));
    ASSERT_TRUE(mf.gridmap.has_value());
    EXPECT_EQ(mf.gridmap->size_x, fin.size_x);
    EXPECT_EQ(mf.gridmap->size_y, fin.size_y);
    EXPECT_FLOAT_EQ(static_cast<float>(mf.gridmap->resolution), 0.1f);
    EXPECT_TRUE(mf.gridmap->cells == fin.cells) << name;
    ASSERT_TRUE(mf.offset.has_value());
    // OFFSET: the world position of cell (0,0)'s corner (first pose + crop).
    EXPECT_NEAR(mf.offset->x, log.geo.world_x(fin.min_x * 4.0), 1e-9);
    EXPECT_NEAR(mf.offset->y, log.geo.world_y(fin.min_y * 4.0), 1e-9);
    ASSERT_TRUE(mf.creator.has_value());
    EXPECT_EQ(mf.creator->origin, "intel.gfs.log.gz");
  }
  const std::string yaml = maptest::read_bytes(dir.file("m.yaml"));
  EXPECT_TRUE(contains(yaml, "image: m.pgm")) << yaml;
  EXPECT_TRUE(contains(yaml, "resolution: 0.1")) << yaml;
}

TEST(Log2Map, BadLogNamesFileAndLineAndLeavesNoOutput) {
  TempDir dir;
  const std::string log = write_text(dir, "bad.log",
                                     "FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1.0 host 1.0\n"
                                     "FLASER 3 1.0 abc 3.0 0 0 0 0 0 0 1.0 host 1.0\n");
  const ToolRun r = log2map({log, dir.file("out.map"), dir.file("out.png")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, "bad.log:2:")) << r.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"bad.log"}));
  // Lenient: the bad line is skipped and reported, the map is written.
  const ToolRun l = log2map({"--lenient", log, dir.file("out.map")});
  EXPECT_EQ(l.status, 0) << l.output;
  EXPECT_TRUE(contains(l.output, "skipped 1 bad line")) << l.output;
}

TEST(Log2Map, MissingLogIsAnError) {
  TempDir dir;
  const ToolRun r = log2map({dir.file("nope.log.gz"), dir.file("out.map")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, "nope.log.gz")) << r.output;
}

TEST(Log2Map, ParameterErrorsNameTheKeyAndWhere) {
  TempDir dir;
  const ToolRun cli = log2map({"--vasco_p_occ", "1.5", kIntel, dir.file("o.map")});
  EXPECT_EQ(cli.status, 2);  // a bad value on the command line is a usage error
  EXPECT_TRUE(contains(cli.output, "vasco_p_occ")) << cli.output;
  const std::string ini = write_text(dir, "bad.ini", "[*]\nvasco_resolution 0.05\nvasco_range_sure 20\n");
  const ToolRun f = log2map({"--param-file", ini, kIntel, dir.file("o.map")});
  EXPECT_EQ(f.status, 1);
  EXPECT_TRUE(contains(f.output, "bad.ini:3")) << f.output;
  EXPECT_TRUE(contains(f.output, "vasco_range_sure")) << f.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"bad.ini"}));
}

TEST(Log2Map, TyposInTheIniAreWarnedAbout) {
  TempDir dir;
  const std::string ini = write_text(dir, "typo.ini", "[*]\nvasco_p_ocupied 0.7\n");
  const ToolRun r = log2map({"--param-file", ini, "--vasco_num_scans", "20", kIntel, dir.file("o.map")});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "typo.ini:2")) << r.output;
  EXPECT_TRUE(contains(r.output, "vasco_p_ocupied")) << r.output;
  EXPECT_TRUE(contains(r.output, "20 scans")) << r.output;
}

TEST(Log2Map, UnwritableOutputFailsBeforeAnyWork) {
  TempDir dir;
  const ToolRun r = log2map({kIntel, dir.file("ok.map"), dir.file("no/such/dir/x.png")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, "x.png")) << r.output;
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Log2Map, CudaWithoutAGpuIsAClearError) {
  TempDir dir;
  const ToolRun v = log2map({"--backend", "cuda", "--vasco_num_scans", "5", kIntel, dir.file("o.map")});
  if (v.status == 0) GTEST_SKIP() << "a GPU is usable here: this checks the no-GPU error";
  EXPECT_EQ(v.status, 1);
  EXPECT_TRUE(contains(v.output, "backend cuda")) << v.output;
  // A CUDA build on a machine without a GPU (or driver) says so in plain
  // words, not in the runtime's "driver version is insufficient".
  if (!contains(v.output, "this build has no CUDA backend")) {
    EXPECT_TRUE(contains(v.output, "no GPU found")) << v.output;
  }
  EXPECT_TRUE(dir.entries().empty());
}


// The precedence every key follows, end to end: the log's PARAM lines select
// the scans unless the ini or the command line says otherwise.
TEST(Log2Map, LogParamsSelectScansBelowIniAndCommandLine) {
  TempDir dir;
  std::string text = "PARAM vasco_num_scans 3 nohost 0\n";
  for (int i = 0; i < 10; ++i)
    text += "FLASER 3 1.0 2.0 3.0 " + std::to_string(0.1 * i) + " 0 0 0 0 0 " + std::to_string(100 + i) + " t 0\n";
  const std::string log = write_text(dir, "p.log", text);
  const std::string ini = write_text(dir, "c.ini", "[*]\nvasco_num_scans 5\n");
  auto scans = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {"--backend", "cpu_double", "--json", "--quiet"});
    args.push_back(log);
    args.push_back(dir.file("out.map"));
    const ToolRun r = log2map(args, false);
    EXPECT_EQ(r.status, 0) << r.output;
    const size_t at = r.output.find("\"scans\":");
    return at == std::string::npos ? -1 : std::atoi(r.output.c_str() + at + 8);
  };
  EXPECT_EQ(scans({}), 3);
  EXPECT_EQ(scans({"--param-file", ini}), 5);
  EXPECT_EQ(scans({"--param-file", ini, "--vasco_num_scans", "7"}), 7);
}

// --resolution M: the written map's cell, by params.h's one rule. The maps
// it makes are compared with maps made by CARMEN's own keys, set by hand to
// what the rule says (0.1 = 0.025 x 4: vasco's defaults; 0.05 = 0.025 x 2;
// a given downsample 1: 0.05 x 1).
TEST(Log2Map, ResolutionSetsTheWrittenCellByOneRule) {
  TempDir dir;
  const auto grid = [&](const std::string &name, std::vector<std::string> args) {
    args.insert(args.begin(), {"--backend", "cpu_threads", "-q", kIntel, dir.file(name)});
    const ToolRun r = log2map(args);
    EXPECT_EQ(r.status, 0) << r.output;
    return *carmen::read_map_file(dir.file(name)).gridmap;
  };
  const auto same = [](const carmen::GridMap &a, const carmen::GridMap &b) {
    return a.size_x == b.size_x && a.size_y == b.size_y && float(a.resolution) == float(b.resolution) &&
           a.cells == b.cells;
  };
  EXPECT_TRUE(same(grid("a.map", {"--resolution", "0.1"}), grid("b.map", {})));
  const carmen::GridMap c = grid("c.map", {"--resolution", "0.05", dir.file("c.pgm")});
  EXPECT_FLOAT_EQ(float(c.resolution), 0.05f);
  EXPECT_TRUE(same(c, grid("d.map", {"--vasco_downsample", "2"})));
  EXPECT_TRUE(contains(maptest::read_bytes(dir.file("c.yaml")), "\nresolution: 0.05\n"));
  const std::string ini = write_text(dir, "one.ini", "[*]\nvasco_downsample 1\n");
  EXPECT_TRUE(same(grid("e.map", {"--param-file", ini, "--resolution", "0.05"}),
                   grid("f.map", {"--vasco_resolution", "0.05", "--vasco_downsample", "1"})));

  for (const std::vector<std::string> &bad : {std::vector<std::string>{"--resolution", "0"},
                                              {"--resolution", "abc"},
                                              {"--resolution", "inf"},
                                              {"--resolution", "1e-9"},
                                              {"--resolution", "0.05", "--vasco_resolution", "0.01"}}) {
    std::vector<std::string> args = bad;
    args.insert(args.end(), {kIntel, dir.file("bad.map")});
    const ToolRun r = log2map(args);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "resolution")) << r.output;
  }
  EXPECT_FALSE(maptest::file_exists(dir.file("bad.map")));
}

TEST(Log2Map, PosesTooFarApartNameTheLogAndLines) {
  TempDir dir;
  const std::string log = write_text(dir, "far.log",
                                     "FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1 t 0\n"
                                     "FLASER 3 1.0 2.0 3.0 50000000 0 0 0 0 0 2 t 0\n");
  const ToolRun r = log2map({"--backend", "cpu_double", log, dir.file("out.map")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, log + ": the poses span")) << r.output;
  EXPECT_TRUE(contains(r.output, "from the scan at line 1 to line 2 in x")) << r.output;
  EXPECT_TRUE(dir.entries() == (std::vector<std::string>{"far.log"}));
}


// A failing run touches no output: `keep.map` exists, `bad.png` is a
// directory; the run is refused before any work and keep.map stays as it was.
TEST(Log2Map, AFailingRunTouchesNoOutput) {
  TempDir dir;
  write_text(dir, "keep.map", "old contents");
  ASSERT_EQ(::mkdir(dir.file("bad.png").c_str(), 0755), 0);
  const ToolRun r = log2map({"--backend", "cpu_double", kIntel, dir.file("keep.map"), dir.file("bad.png")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, "bad.png: is a directory")) << r.output;
  std::ifstream in(dir.file("keep.map"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "old contents");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"bad.png", "keep.map"}));
}

// A PGM whose YAML cannot be written: neither file appears.
TEST(Log2Map, APgmWithoutItsYamlIsNeverWritten) {
  TempDir dir;
  ASSERT_EQ(::mkdir(dir.file("out.yaml").c_str(), 0755), 0);
  const ToolRun r = log2map({"--backend", "cpu_double", kIntel, dir.file("out.pgm")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, "out.yaml: is a directory")) << r.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"out.yaml"}));
}


// Two scans 399 m apart (diagonally) ask for a grid of 10^9 cells, 4.5 GiB
// on cpu_double: refused by the default memory budget before anything is
// allocated, naming the need, the bytes a cell and the scans that stretch it.
TEST(Log2Map, AGridBeyondTheMemoryBudgetIsRefusedNamingTheLog) {
  TempDir dir;
  const std::string log = write_text(dir, "far.log",
                                     "FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1 t 0\n"
                                     "FLASER 3 1.0 2.0 3.0 399 399 0 0 0 0 2 t 0\n");
  const ToolRun r = log2map({"--backend", "cpu_double", log, dir.file("out.map")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, log + ": the map needs about 4")) << r.output;
  EXPECT_TRUE(contains(r.output, "4.5 bytes a cell on cpu_double")) << r.output;
  EXPECT_TRUE(contains(r.output, "the poses span 798 m x 798 m (from the scan at line 1 to line 2 in x")) << r.output;
  EXPECT_TRUE(contains(r.output, "--max-memory")) << r.output;
  const ToolRun small = log2map({"--backend", "cpu_double", "--max-memory", "1", kIntel, dir.file("out.map")});
  EXPECT_EQ(small.status, 1);
  EXPECT_TRUE(contains(small.output, "more than the budget of 1 MiB")) << small.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"far.log"}));
}


// --max-memory bounds what is read too: a log of long scans is refused at
// the scan that passes the budget, naming the log's line, not loaded first
// (3000 scans of 100000 beams reached 2.8 GB with --max-memory 100).
TEST(Log2Map, TheMemoryBudgetIsCountedWhileTheLogIsRead) {
  TempDir dir;
  std::string scan = "FLASER 20000";
  for (int i = 0; i < 20000; ++i) scan += " 1.5";
  scan += " 0 0 0 0 0 0 1 t 0\n";
  std::string text;
  for (int i = 0; i < 40; ++i) text += scan;  // 80 KB of ranges a scan: 3.2 MB in all
  const std::string log = write_text(dir, "long.log", text);
  const ToolRun r = log2map({"--backend", "cpu_double", "--max-memory", "1", log, dir.file("out.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, log + ":1")) << r.output;  // a line of the log, "long.log:1N: ..."
  EXPECT_TRUE(contains(r.output, "(1.07 MiB), more than the memory budget of 1048576 bytes (1 MiB); raise it with "
                                 "--max-memory"))
      << r.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"long.log"}));
}

// A log whose every beam CARMEN skips (50 m or more, +inf, NaN, 1e308 as a
// float) maps nothing: the error names the log and says why (it said
// "gridmap size 0 x 0 is not positive", naming no file); nothing is written.
TEST(Log2Map, ALogWhoseEveryBeamIsSkippedSaysWhy) {
  TempDir dir;
  const std::string log = write_text(dir, "far.log",
                                     "FLASER 3 50.0 1e308 nan 0 0 0 0 0 0 1 t 0\n"
                                     "FLASER 3 60 inf 75.5 0.5 0 0 0.5 0 0 2 t 0\n");
  const ToolRun r = log2map({"--backend", "cpu_double", log, dir.file("out.map"), dir.file("out.png")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, log + ": no beam updated any cell: every one of the 6 ranges of the 2 scans"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "50 m or more, NaN or +inf")) << r.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"far.log"}));
}

// The small defects of the reliability audit, each with its reproduction.
TEST(Log2Map, SmallDefectsGiveClearErrors) {
  TempDir dir;
  // --threads 100000: a usage error, not a raw errno.
  EXPECT_EQ(log2map({"--threads", "100000", kIntel, dir.file("a.map")}).status, 2);
  // vasco_downsample larger than the grid and range_max 0 name the key.
  // Every bad --vasco_KEY value is the command line's fault, so a usage error
  // (exit 2), this one too, though it takes the log's grid to see it.
  const ToolRun ds = log2map({"--vasco_downsample", "1000000", kIntel, dir.file("a.map")});
  EXPECT_EQ(ds.status, 2);
  EXPECT_TRUE(contains(ds.output, "command line: vasco_downsample = 1000000 is larger than the grid")) << ds.output;
  const ToolRun rm = log2map({"--vasco_range_max", "0", kIntel, dir.file("a.map")});
  EXPECT_EQ(rm.status, 2);
  EXPECT_TRUE(contains(rm.output, "vasco_range_max = 0")) << rm.output;
  // vasco_first_scan near LONG_MAX: no overflow, a clear "nothing selected".
  const ToolRun fs = log2map({"--vasco_first_scan", "9223372036854775800", "--vasco_num_scans", "100", kIntel,
                              dir.file("a.map")});
  EXPECT_EQ(fs.status, 1);
  EXPECT_TRUE(contains(fs.output, "no FLASER or ROBOTLASER1 scans to map in the selected range")) << fs.output;
  EXPECT_TRUE(dir.entries().empty());
}

// A hostile file's escape sequences reach the terminal escaped.
TEST(Log2Map, EscapeCodesFromAFileAreNotEchoedRaw) {
  TempDir dir;
  const std::string ini = write_text(dir, "esc.ini", "[*]\nvasco_p_occ \x1b[31mRED\n");
  const ToolRun r = log2map({"--backend", "cpu_double", "--param-file", ini, kIntel, dir.file("out.map")});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.output.find('\x1b'), std::string::npos) << r.output;
  EXPECT_TRUE(contains(r.output, "\\x1b[31mRED")) << r.output;
}
}  // namespace
