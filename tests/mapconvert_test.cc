// The mapconvert tool, run as a program.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <cstdio>
#include <string>

#include "carmen_compat/map_file.h"
#include "map_test_support.h"
#include "tool_support.h"

namespace {

using maptest::map_fixture;
using maptest::read_bytes;
using maptest::TempDir;

using tooltest::contains;
using tooltest::ToolRun;

ToolRun mapconvert(const std::vector<std::string> &args, bool with_stderr = true) {
  return tooltest::run_tool("mapconvert", args, with_stderr);
}

class MapConvert : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!maptest::file_exists(std::string(VASCO_BIN_DIR) + "/mapconvert")) {
      GTEST_SKIP() << "mapconvert is not built in " << VASCO_BIN_DIR;
    }
  }
};

TEST_F(MapConvert, Usage) {
  const ToolRun help = mapconvert({"--help"});
  EXPECT_EQ(help.status, 0);
  EXPECT_TRUE(contains(help.output, "Usage: mapconvert")) << help.output;
  EXPECT_EQ(mapconvert({}).status, 2);
  EXPECT_EQ(mapconvert({"only-one.map"}).status, 2);
  EXPECT_EQ(mapconvert({"a.map", "b.map", "c.map"}).status, 2);
  EXPECT_EQ(mapconvert({"--info"}).status, 2);
  EXPECT_EQ(mapconvert({"--bogus", "a.map", "b.map"}).status, 2);
  EXPECT_EQ(mapconvert({"--mode", "fancy", "a.map", "b.pgm"}).status, 2);
  EXPECT_EQ(mapconvert({"--mode", "raw", "a.map", "b.png"}).status, 2);  // mode is for .pgm only
  const ToolRun ext = mapconvert({map_fixture("freiburg.map"), "out.jpg"});
  EXPECT_EQ(ext.status, 2);
  EXPECT_TRUE(contains(ext.output, "out.jpg")) << ext.output;
}

TEST_F(MapConvert, VersionAndQuiet) {
  const ToolRun v = mapconvert({"--version"});
  EXPECT_EQ(v.status, 0);
  EXPECT_EQ(v.output.rfind("mapconvert (vasco_gpu) ", 0), 0u) << v.output;
  TempDir dir;
  const ToolRun q = mapconvert({"-q", map_fixture("freiburg.map"), dir.file("f.map")});
  EXPECT_EQ(q.status, 0) << q.output;
  EXPECT_EQ(q.output, "");
  EXPECT_TRUE(maptest::file_exists(dir.file("f.map")));
}

// "-": a map from standard input, a CARMEN map to standard output.
TEST_F(MapConvert, DashIsStandardInputAndOutput) {
  TempDir dir;
  const std::string out = dir.file("out.map");
  ASSERT_EQ(tooltest::run_tool_piped(map_fixture("freiburg.map"), "mapconvert", {"-", "-"}, out), 0)
      << read_bytes(out + ".err");
  const carmen::MapFile a = carmen::read_map_file(out), b = carmen::read_map_file(map_fixture("freiburg.map"));
  ASSERT_TRUE(a.gridmap && b.gridmap);
  EXPECT_EQ(a.gridmap->cells, b.gridmap->cells);
  ASSERT_EQ(tooltest::run_tool_piped(map_fixture("freiburg.map"), "mapconvert", {"-", dir.file("f.png")}, out), 0);
  EXPECT_TRUE(maptest::file_exists(dir.file("f.png")));
}

TEST_F(MapConvert, InfoOnFreiburg) {
  const ToolRun r = mapconvert({"--info", map_fixture("freiburg.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "size: 300 x 300 cells")) << r.output;
  EXPECT_TRUE(contains(r.output, "resolution: 0.1")) << r.output;
  EXPECT_TRUE(contains(r.output, "GRIDMAP")) << r.output;
  EXPECT_TRUE(contains(r.output, "CREATOR")) << r.output;
  // 44740 unknown cells of 90000 (counted from the raw bytes: see map_file_test).
  EXPECT_TRUE(contains(r.output, "unknown: 44740 of 90000 cells (49.71%)")) << r.output;
  EXPECT_TRUE(contains(r.output, "known values: min 0.004")) << r.output;
  EXPECT_TRUE(contains(r.output, "max 1\n")) << r.output;
}

TEST_F(MapConvert, ConvertsToEveryFormat) {
  TempDir dir;
  const std::string src = map_fixture("freiburg.map");
  for (const char *name : {"fr.map", "fr.map.gz", "fr.pgm", "fr.png"}) {
    const ToolRun r = mapconvert({src, dir.file(name)});
    EXPECT_EQ(r.status, 0) << name << ": " << r.output;
    EXPECT_TRUE(maptest::file_exists(dir.file(name))) << name;
  }
  EXPECT_EQ(read_bytes(dir.file("fr.map")), read_bytes(src));  // nothing lost or changed
  EXPECT_EQ(maptest::gunzip_file(dir.file("fr.map.gz")), read_bytes(src));
  EXPECT_EQ(read_bytes(dir.file("fr.pgm")).substr(0, 15), "P5\n300 300\n255\n");
  EXPECT_EQ(read_bytes(dir.file("fr.pgm")).size(), 15u + 90000u);
  const std::string yaml = read_bytes(dir.file("fr.yaml"));
  EXPECT_TRUE(contains(yaml, "image: fr.pgm\n")) << yaml;
  EXPECT_TRUE(contains(yaml, "mode: trinary\n")) << yaml;
  EXPECT_EQ(read_bytes(dir.file("fr.png")).substr(1, 3), "PNG");
  // And back: the gzip copy converts to the same map.
  const ToolRun back = mapconvert({dir.file("fr.map.gz"), dir.file("back.map")});
  EXPECT_EQ(back.status, 0) << back.output;
  EXPECT_EQ(read_bytes(dir.file("back.map")), read_bytes(src));
}

TEST_F(MapConvert, PgmModeAndOffsetOrigin) {
  TempDir dir;
  carmen::MapFile m;
  m.gridmap = carmen::GridMap::filled(2, 1, 0.25, 0.5f);
  m.offset = carmen::GlobalOffset{-3.5, 1.25, 0};
  carmen::write_map_file(dir.file("in.map"), m);
  const ToolRun r = mapconvert({"--mode", "raw", dir.file("in.map"), dir.file("out.pgm")});
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string yaml = read_bytes(dir.file("out.yaml"));
  EXPECT_TRUE(contains(yaml, "mode: raw\n")) << yaml;
  EXPECT_TRUE(contains(yaml, "origin: [-3.5, 1.25, 0.0]\n")) << yaml;
  EXPECT_TRUE(contains(yaml, "resolution: 0.25\n")) << yaml;
  EXPECT_EQ(read_bytes(dir.file("out.pgm")), std::string("P5\n2 1\n255\n") + char(50) + char(50));
}

// A gmapping map (origin [-100, -100, 0], 10 m cells here) through
// mapconvert, .yaml -> .map -> .yaml: every number comes back as a YAML 1.1
// float with the same value (was "-1e+02" and "1e+01", strings to PyYAML).
TEST_F(MapConvert, YamlRoundTripKeepsNumbersAsFloats) {
  TempDir dir;
  maptest::write_bytes(dir.file("g.pgm"), std::string("P5\n2 1\n255\n") + char(0) + char(254));
  maptest::write_bytes(dir.file("g.yaml"), "image: g.pgm\nresolution: 10\norigin: [-100, -100, 0]\n"
                                           "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n");
  ToolRun r = mapconvert({dir.file("g.yaml"), dir.file("g.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  r = mapconvert({dir.file("g.map"), dir.file("back.pgm")});
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string yaml = read_bytes(dir.file("back.yaml"));
  EXPECT_TRUE(contains(yaml, "\norigin: [-100.0, -100.0, 0.0]\n")) << yaml;
  EXPECT_TRUE(contains(yaml, "\nresolution: 10.0\n")) << yaml;
  EXPECT_TRUE(contains(yaml, "\noccupied_thresh: 0.65\n")) << yaml;
  EXPECT_TRUE(contains(yaml, "\nfree_thresh: 0.196\n")) << yaml;
}

TEST_F(MapConvert, BadInputExitsOneNamingTheFile) {
  TempDir dir;
  for (const char *name : {"longwood", "nsh_level_3", "thickwean", "wean5300"}) {
    const std::string file = map_fixture(std::string("damaged/") + name + ".map.gz");
    const ToolRun info = mapconvert({"--info", file});
    EXPECT_EQ(info.status, 1) << name;
    EXPECT_TRUE(contains(info.output, file)) << info.output;
    const ToolRun conv = mapconvert({file, dir.file("x.png")});
    EXPECT_EQ(conv.status, 1) << name;
  }
  EXPECT_TRUE(dir.entries().empty());  // nothing written for a bad input
  const ToolRun missing = mapconvert({dir.file("nope.map"), dir.file("x.map")});
  EXPECT_EQ(missing.status, 1);
  EXPECT_TRUE(contains(missing.output, dir.file("nope.map"))) << missing.output;
  // An output that cannot be written.
  const ToolRun unwritable = mapconvert({map_fixture("freiburg.map"), dir.file("no/dir/x.png")});
  EXPECT_EQ(unwritable.status, 1);
  EXPECT_TRUE(contains(unwritable.output, dir.file("no/dir/x.png"))) << unwritable.output;
  // A map without a grid cannot become an image.
  carmen::write_map_file(dir.file("nogrid.map"), carmen::MapFile{});
  const ToolRun nogrid = mapconvert({dir.file("nogrid.map"), dir.file("x.pgm")});
  EXPECT_EQ(nogrid.status, 1);
  EXPECT_TRUE(contains(nogrid.output, "GRIDMAP")) << nogrid.output;
}

// The output must not be the input (by device and inode, however spelled,
// a .pgm's .yaml included), nor a FIFO: refused before anything is written.
TEST_F(MapConvert, AnOutputThatIsTheInputOrSpecialIsRefused) {
  TempDir dir;
  const std::string in = dir.file("m.map");
  maptest::write_bytes(in, read_bytes(map_fixture("freiburg.map")));
  const std::string bytes = read_bytes(in);
  const ToolRun same = mapconvert({in, dir.path() + "/./m.map"});
  EXPECT_EQ(same.status, 2) << same.output;
  EXPECT_TRUE(contains(same.output, "is the input")) << same.output;
  ASSERT_EQ(::rename(in.c_str(), dir.file("m.yaml").c_str()), 0);
  const ToolRun yaml = mapconvert({dir.file("m.yaml"), dir.file("m.pgm")});  // m.pgm writes m.yaml
  EXPECT_EQ(yaml.status, 2) << yaml.output;
  EXPECT_EQ(read_bytes(dir.file("m.yaml")), bytes);
  ASSERT_EQ(::mkfifo(dir.file("p.png").c_str(), 0600), 0);
  const ToolRun fifo = mapconvert({dir.file("m.yaml"), dir.file("p.png")});
  EXPECT_EQ(fifo.status, 1) << fifo.output;
  EXPECT_TRUE(contains(fifo.output, "is a FIFO")) << fifo.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"m.yaml", "p.png"}));
}

// --free-thresh, --occupied-thresh, --negate: usage errors (exit 2) name
// the option and write nothing.
TEST_F(MapConvert, ThresholdOptionsAreChecked) {
  TempDir dir;
  const std::string in = map_fixture("freiburg.map");
  const auto refused = [&](const std::vector<std::string> &args, const std::string &words) {
    const ToolRun r = mapconvert(args);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, words)) << r.output;
  };
  refused({"--free-thresh", "0.7", in, dir.file("a.pgm")}, "--free-thresh 0.7 must be below --occupied-thresh 0.65");
  refused({"--occupied-thresh", "1.5", in, dir.file("a.pgm")}, "--occupied-thresh 1.5: must be a number from 0 to 1");
  refused({"--free-thresh=-0.1", in, dir.file("a.yaml")}, "--free-thresh -0.1");
  refused({"--free-thresh", "half", in, dir.file("a.pgm")}, "--free-thresh 'half'");
  refused({"--free-thresh", in, dir.file("a.pgm")}, "");  // the value is missing: IN taken as it
  refused({"--negate", "--mode", "raw", in, dir.file("a.pgm")}, "--negate");
  refused({"--negate", in, dir.file("a.map")}, ".pgm, .png+yaml and .yaml output only");
  refused({"--free-thresh", "0.2", in, dir.file("a.png")}, ".pgm, .png+yaml and .yaml output only");
  EXPECT_TRUE(dir.entries().empty());
  const ToolRun ok = mapconvert({"--free-thresh", "0.25", "--occupied-thresh=0.7", "--negate", in, dir.file("n.png+yaml")});
  ASSERT_EQ(ok.status, 0) << ok.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"n.png", "n.yaml"}));
  const std::string yaml = read_bytes(dir.file("n.yaml"));
  EXPECT_TRUE(contains(yaml, "free_thresh: 0.25\n")) << yaml;
  EXPECT_TRUE(contains(yaml, "occupied_thresh: 0.7\n")) << yaml;
  EXPECT_TRUE(contains(yaml, "negate: 1\n")) << yaml;
  EXPECT_TRUE(contains(yaml, "image: n.png\n")) << yaml;
}

// The cells' classes: unknown, free (p < free_thresh), occupied (p >
// occupied_thresh), in between.
int cell_class(float v) { return v < 0 ? 0 : v < 0.196 ? 1 : v > 0.65 ? 2 : 3; }

// log2map's .pgm + .yaml, back to a CARMEN map through the YAML: the same
// size, resolution and origin, and every cell in its class (trinary: in
// between reads as unknown, as map_server reads it).
TEST_F(MapConvert, Log2MapPgmRoundTripsThroughTheYaml) {
  TempDir dir;
  const ToolRun made = tooltest::run_tool(
      "log2map", {"--backend", "cpu_threads", "-q", std::string(VASCO_LOGS_DIR) + "/intel.gfs.log.gz",
                  dir.file("m.map"), dir.file("m.pgm")});
  ASSERT_EQ(made.status, 0) << made.output;
  const ToolRun r = mapconvert({dir.file("m.yaml"), dir.file("back.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  const carmen::MapFile a = carmen::read_map_file(dir.file("m.map")), b = carmen::read_map_file(dir.file("back.map"));
  ASSERT_TRUE(a.gridmap && b.gridmap && a.offset && b.offset);
  ASSERT_EQ(a.gridmap->size_x, b.gridmap->size_x);
  ASSERT_EQ(a.gridmap->size_y, b.gridmap->size_y);
  EXPECT_FLOAT_EQ(float(a.gridmap->resolution), float(b.gridmap->resolution));
  // The YAML writes the origin's double exactly (the .map's OFFSET is a
  // double), though intel's origin has more digits than a float holds.
  EXPECT_EQ(a.offset->x, b.offset->x);
  EXPECT_EQ(a.offset->y, b.offset->y);
  EXPECT_NE(double(float(a.offset->y)), a.offset->y) << "a float would keep this origin: the test would not see it cut";
  ASSERT_TRUE(b.creator);
  EXPECT_EQ(b.creator->origin, "m.yaml");
  size_t counts[4] = {0, 0, 0, 0};
  for (size_t i = 0; i < a.gridmap->cells.size(); ++i) {
    const int ca = cell_class(a.gridmap->cells[i]), cb = cell_class(b.gridmap->cells[i]);
    ++counts[ca];
    ASSERT_EQ(cb, ca == 3 ? 0 : ca) << "cell " << i << ": " << a.gridmap->cells[i] << " came back as "
                                    << b.gridmap->cells[i];
  }
  EXPECT_GT(counts[0], 1000u);
  EXPECT_GT(counts[1], 1000u);
  EXPECT_GT(counts[2], 1000u);
  // Scale mode in a PNG: unknown stays unknown, p within a grey level.
  ASSERT_EQ(mapconvert({"--mode", "scale", dir.file("m.map"), dir.file("s.png+yaml")}).status, 0);
  ASSERT_EQ(mapconvert({dir.file("s.png+yaml"), dir.file("s.map")}).status, 0);
  const carmen::MapFile s = carmen::read_map_file(dir.file("s.map"));
  ASSERT_TRUE(s.gridmap);
  for (size_t i = 0; i < a.gridmap->cells.size(); ++i) {
    const float va = a.gridmap->cells[i], vs = s.gridmap->cells[i];
    if (va < 0) {
      ASSERT_EQ(vs, -1.0f) << "cell " << i;
    } else {
      ASSERT_NEAR(vs, va, 0.5 / 255 + 1e-6) << "cell " << i;
    }
  }
}

TEST_F(MapConvert, YamlInputErrorsExitOneNamingTheFile) {
  TempDir dir;
  maptest::write_bytes(dir.file("a.yaml"), "image: gone.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n");
  ToolRun r = mapconvert({dir.file("a.yaml"), dir.file("a.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, dir.file("a.yaml") + ":1:")) << r.output;
  EXPECT_TRUE(contains(r.output, "gone.pgm")) << r.output;
  maptest::write_bytes(dir.file("b.yaml"), "image: b.pgm\nresolution: 0.1\norigin: [0, 0]\n");
  maptest::write_bytes(dir.file("b.pgm"), "P5\n2 2\n255\nab");  // cut short
  r = mapconvert({dir.file("b.yaml"), dir.file("b.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, dir.file("b.yaml") + ":3:")) << r.output;
  maptest::write_bytes(dir.file("b.yaml"), "image: b.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n");
  r = mapconvert({dir.file("b.yaml"), dir.file("b.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, dir.file("b.pgm"))) << r.output;
  EXPECT_TRUE(contains(r.output, "cut short")) << r.output;
  EXPECT_FALSE(maptest::file_exists(dir.file("b.map")));
  // A picture holds no resolution: a usage error. Writing over the input: refused.
  ASSERT_EQ(mapconvert({map_fixture("freiburg.map"), dir.file("p.png")}).status, 0);
  r = mapconvert({dir.file("p.png"), dir.file("p.map")});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "picture")) << r.output;
  ASSERT_EQ(mapconvert({map_fixture("freiburg.map"), dir.file("f.pgm")}).status, 0);
  r = mapconvert({dir.file("f.yaml"), dir.file("f.png+yaml")});  // would overwrite f.yaml
  EXPECT_NE(r.status, 0) << r.output;
  const ToolRun info = mapconvert({"--info", dir.file("f.yaml")});
  EXPECT_EQ(info.status, 0) << info.output;
  EXPECT_TRUE(contains(info.output, "size: 300 x 300 cells")) << info.output;
  EXPECT_TRUE(contains(info.output, "format: ROS map_server YAML")) << info.output;
}

// log2map's map_server options: usage errors exit 2 naming the option and
// write nothing; the values reach the YAML; a warning when no output uses them.
TEST_F(MapConvert, Log2MapThresholdOptions) {
  TempDir dir;
  const std::string log = std::string(VASCO_LOGS_DIR) + "/intel.gfs.log.gz";
  const auto log2map = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {"--backend", "cpu_threads", "-q"});
    return tooltest::run_tool("log2map", args);
  };
  ToolRun r = log2map({"--free-thresh", "0.8", log, dir.file("m.pgm")});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "--free-thresh 0.8 must be below --occupied-thresh 0.65")) << r.output;
  r = log2map({"--occupied-thresh", "2", log, dir.file("m.pgm")});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "--occupied-thresh 2")) << r.output;
  r = log2map({"--free-thresh", "x", log, dir.file("m.pgm")});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "--free-thresh")) << r.output;
  r = log2map({"--negate", "--mode", "raw", log, dir.file("m.pgm")});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(dir.entries().empty());
  r = log2map({"--free-thresh", "0.25", "--negate", log, dir.file("m.yaml"), dir.file("m.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"m.map", "m.pgm", "m.yaml"}));
  const std::string yaml = read_bytes(dir.file("m.yaml"));
  EXPECT_TRUE(contains(yaml, "free_thresh: 0.25\n")) << yaml;
  EXPECT_TRUE(contains(yaml, "negate: 1\n")) << yaml;
  EXPECT_TRUE(contains(yaml, "image: m.pgm\n")) << yaml;
  r = log2map({"--free-thresh", "0.25", log, dir.file("only.map")});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "warning: --mode, --free-thresh")) << r.output;
}

}  // namespace
