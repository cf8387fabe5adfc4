// carmen_compat/map_format.h: the format table, its extension rule, every
// format's round trip, and damaged inputs.
#include "carmen_compat/map_format.h"

#include <gtest/gtest.h>

#include <fstream>
#include <png.h>

#include <cstring>

#include "carmen_compat/error.h"
#include "carmen_compat/map_file.h"
#include "map_test_support.h"

namespace {

using maptest::map_fixture;
using maptest::read_bytes;
using maptest::TempDir;
using maptest::write_bytes;

// 3 x 2 cells whose values every lossless format keeps: unknown, free,
// occupied, and p = 1 - 51/255 (PNG level 51, exact in float arithmetic
// as the PNG reader computes it).
carmen::MapToWrite sample() {
  carmen::MapToWrite m;
  m.grid = carmen::GridMap::filled(3, 2, 0.05);
  m.grid.at(0, 0) = 0.0f;
  m.grid.at(1, 0) = 1.0f;
  m.grid.at(2, 1) = 1.0f - 51.0f / 255.0f;
  m.origin = carmen::GlobalOffset{-12.5, 3.25, 0};
  m.author = "test";
  m.source = "unit";
  m.description = "a sample";
  m.time = 1700000000;
  return m;
}

TEST(MapFormat, TableListsEveryFormat) {
  EXPECT_EQ(carmen::known_map_extensions(), ".map, .map.gz, .pgm, .png+yaml, .yaml, .png");
  ASSERT_NE(carmen::find_map_format("a/b.map.gz"), nullptr);
  EXPECT_EQ(carmen::find_map_format("a/b.map.gz")->format, carmen::MapFormat::CarmenMapGz);
  EXPECT_EQ(carmen::find_map_format("b.map")->format, carmen::MapFormat::CarmenMap);
  EXPECT_EQ(carmen::find_map_format("b.pgm")->format, carmen::MapFormat::PgmYaml);
  EXPECT_EQ(carmen::find_map_format("b.png")->format, carmen::MapFormat::Png);
  EXPECT_EQ(carmen::find_map_format("b.png+yaml")->format, carmen::MapFormat::PngYaml);
  EXPECT_EQ(carmen::find_map_format("b.yaml")->format, carmen::MapFormat::Yaml);
  EXPECT_EQ(carmen::find_map_format("B.PNG+YAML")->format, carmen::MapFormat::PngYaml);
}

// The files each name stands for: NAME.png+yaml is NAME.png and NAME.yaml
// (NAME.png alone stays the picture), NAME.yaml written is NAME.pgm too.
TEST(MapFormat, OutputAndInputFiles) {
  EXPECT_EQ(carmen::map_output_files("d/x.png+yaml"), (std::vector<std::string>{"d/x.png", "d/x.yaml"}));
  EXPECT_EQ(carmen::map_output_files("d/x.yaml"), (std::vector<std::string>{"d/x.yaml", "d/x.pgm"}));
  EXPECT_EQ(carmen::map_output_files("d/x.png"), (std::vector<std::string>{"d/x.png"}));
  TempDir dir;
  write_bytes(dir.file("y.yaml"), "image: pics/y.png\nresolution: 0.1\norigin: [0, 0, 0]\n");
  EXPECT_EQ(carmen::map_input_files(dir.file("y.yaml")),
            (std::vector<std::string>{dir.file("y.yaml"), dir.file("pics/y.png")}));
  EXPECT_EQ(carmen::map_input_files(dir.file("none.yaml")), (std::vector<std::string>{dir.file("none.yaml")}));
  EXPECT_EQ(carmen::map_input_files("x.pgm"), (std::vector<std::string>{"x.pgm", "x.yaml"}));
}

TEST(MapFormat, ExtensionsIgnoreCase) {
  EXPECT_EQ(carmen::find_map_format("X.PNG")->format, carmen::MapFormat::Png);
  EXPECT_EQ(carmen::find_map_format("x.Map.Gz")->format, carmen::MapFormat::CarmenMapGz);
  EXPECT_EQ(carmen::find_map_format("x.MAP")->format, carmen::MapFormat::CarmenMap);
  EXPECT_EQ(carmen::find_map_format("x.PGM")->format, carmen::MapFormat::PgmYaml);
  EXPECT_EQ(carmen::map_output_files("d/x.PGM"), (std::vector<std::string>{"d/x.PGM", "d/x.yaml"}));
}

TEST(MapFormat, UnknownExtensionIsAUsageErrorListingTheKnownOnes) {
  for (const std::string path : {"x.bmp", "x.map.bz2", "map", "x.gz", ""}) {
    EXPECT_EQ(carmen::find_map_format(path), nullptr) << path;
    try {
      carmen::read_map(path);
      ADD_FAILURE() << path << " was accepted";
    } catch (const carmen::Error &e) {
      EXPECT_EQ(e.code(), carmen::ErrorCode::Usage) << e.what();
      EXPECT_NE(std::string(e.what()).find(".map, .map.gz, .pgm, .png+yaml, .yaml, .png"), std::string::npos)
          << e.what();
    }
  }
  TempDir dir;
  EXPECT_THROW(carmen::write_map(dir.file("x.tiff"), sample()), carmen::Error);
  EXPECT_TRUE(dir.entries().empty());
}

void expect_same_cells(const carmen::GridMap &a, const carmen::GridMap &b) {
  ASSERT_EQ(a.size_x, b.size_x);
  ASSERT_EQ(a.size_y, b.size_y);
  for (size_t i = 0; i < a.cells.size(); ++i) EXPECT_EQ(a.cells[i], b.cells[i]) << "cell " << i;
}

class MapFormatRoundTrip : public ::testing::TestWithParam<const char *> {};

TEST_P(MapFormatRoundTrip, CellsAndOriginComeBack) {
  TempDir dir;
  const std::string path = dir.file(std::string("m") + GetParam());
  const carmen::MapToWrite m = sample();
  carmen::write_map(path, m);
  const carmen::MapRead r = carmen::read_map(path);
  const carmen::MapFormat f = carmen::map_format_of(path).format;
  if (f == carmen::MapFormat::PgmYaml || f == carmen::MapFormat::PngYaml || f == carmen::MapFormat::Yaml) {
    // Trinary keeps unknown, free and occupied; 0.8 is occupied.
    carmen::GridMap want = m.grid;
    want.at(2, 1) = 1.0f;
    expect_same_cells(r.grid, want);
  } else {
    expect_same_cells(r.grid, m.grid);
  }
  if (f == carmen::MapFormat::Png) {
    EXPECT_FALSE(r.origin);
    EXPECT_EQ(r.grid.resolution, 0.0);
  } else {
    ASSERT_TRUE(r.origin);
    EXPECT_EQ(r.origin->x, -12.5);
    EXPECT_EQ(r.origin->y, 3.25);
    EXPECT_FLOAT_EQ(float(r.grid.resolution), 0.05f);
  }
}

INSTANTIATE_TEST_SUITE_P(EveryFormat, MapFormatRoundTrip,
                         ::testing::Values(".map", ".map.gz", ".pgm", ".png", ".png+yaml", ".yaml", ".MAP.GZ", ".PNG",
                                           ".Pgm", ".PNG+YAML"));

TEST(MapFormat, AResolutionAFloat32CannotHoldIsRefusedBeforeWriting) {
  TempDir dir;
  for (double res : {1e-300, 1e300, 0.0, -0.05}) {
    carmen::MapToWrite m = sample();
    m.grid.resolution = res;
    for (const char *name : {"m.map", "m.map.gz"}) {
      try {
        carmen::write_map(dir.file(name), m);
        ADD_FAILURE() << res << " " << name << " written";
      } catch (const carmen::FileError &e) {
        EXPECT_NE(std::string(e.what()).find("does not fit a CARMEN map"), std::string::npos) << e.what();
      }
      EXPECT_FALSE(std::ifstream(dir.file(name)).good()) << res;
    }
  }
}

TEST(MapFormat, UpperCaseGzIsReallyGzip) {
  TempDir dir;
  carmen::write_map(dir.file("m.MAP.GZ"), sample());
  EXPECT_EQ(read_bytes(dir.file("m.MAP.GZ")).substr(0, 2), std::string("\x1f\x8b", 2));
  EXPECT_EQ(maptest::gunzip_file(dir.file("m.MAP.GZ")).substr(0, 1), "#");
}

TEST(MapFormat, CarmenMapHoldsCommentsCreatorAndOffset) {
  TempDir dir;
  carmen::MapToWrite m = sample();
  m.creator_origin = "python";
  carmen::write_map(dir.file("m.map"), m);
  const carmen::MapFile f = carmen::read_map_file(dir.file("m.map"));
  ASSERT_TRUE(f.creator);
  EXPECT_EQ(f.creator->user, "test");
  EXPECT_EQ(f.creator->origin, "python");
  EXPECT_EQ(f.creator->description, "a sample");
  EXPECT_EQ(f.creator->time, 1700000000);
  EXPECT_EQ(f.comments, carmen::standard_map_comments(3, 2, 0.05, "unit", "a sample", "test", 1700000000));
  ASSERT_TRUE(f.offset);
  EXPECT_EQ(f.offset->x, -12.5);
  m.origin.reset();
  carmen::write_map(dir.file("n.map"), m);
  EXPECT_FALSE(carmen::read_map_file(dir.file("n.map")).offset);
}

TEST(MapFormat, PgmScaleAndRawModesRoundTrip) {
  TempDir dir;
  carmen::MapToWrite m = sample();
  m.grid.at(2, 1) = 0.25f;  // raw level 25, read back as 25 / 100
  m.pgm_mode = carmen::PgmMode::Raw;
  carmen::write_map(dir.file("raw.pgm"), m);
  expect_same_cells(carmen::read_map(dir.file("raw.pgm")).grid, m.grid);
  m.grid.at(2, 1) = 1.0f - 51.0f / 255.0f;  // scale level 51
  m.pgm_mode = carmen::PgmMode::Scale;
  carmen::write_map(dir.file("scale.pgm"), m);
  const carmen::GridMap g = carmen::read_map(dir.file("scale.pgm")).grid;
  EXPECT_EQ(g.at(0, 1), -1.0f);
  EXPECT_EQ(g.at(0, 0), 0.0f);
  EXPECT_EQ(g.at(1, 0), 1.0f);
  EXPECT_FLOAT_EQ(g.at(2, 1), float((255 - 51) / 255.0));
}

// A hand-written map_server pair (comments, negate, another key order).
TEST(MapFormat, PgmReaderTakesMapServerYaml) {
  TempDir dir;
  write_bytes(dir.file("h.pgm"), std::string("P5\n# made by hand\n2 1\n255\n") + std::string("\x00\xfe", 2));
  write_bytes(dir.file("h.yaml"),
              "# a map\nimage: \"h.pgm\"\nnegate: 1\norigin: [1.5, -2, 0.0]  # corner\nresolution: 0.1\n");
  const carmen::MapRead r = carmen::read_map(dir.file("h.pgm"));
  // negate 1: occ = v / 255: level 0 free, level 254 occupied.
  EXPECT_EQ(r.grid.at(0, 0), 0.0f);
  EXPECT_EQ(r.grid.at(1, 0), 1.0f);
  EXPECT_EQ(r.origin->x, 1.5);
  EXPECT_EQ(r.origin->y, -2.0);
  EXPECT_DOUBLE_EQ(r.grid.resolution, 0.1);
}

void expect_file_error(const std::string &path, const std::string &names, const std::string &words, long line = 0) {
  try {
    carmen::read_map(path);
    ADD_FAILURE() << path << " was accepted";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), names) << e.what();
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    if (line > 0) {
      EXPECT_EQ(e.line(), line) << e.what();
    }
  }
}

TEST(MapFormatBad, DamagedCarmenMapsNameTheFile) {
  for (const char *name : {"longwood.map.gz", "nsh_level_3.map.gz", "thickwean.map.gz", "wean5300.map.gz"}) {
    const std::string path = map_fixture(std::string("damaged/") + name);
    expect_file_error(path, path, "");
  }
  TempDir dir;
  write_bytes(dir.file("empty.map"), "");
  expect_file_error(dir.file("empty.map"), dir.file("empty.map"), "empty");
  expect_file_error(dir.file("missing.map"), dir.file("missing.map"), "cannot open");
}

// A CARMEN map cut short inside its cells reads as CARMEN renders it (the
// rest of the cells unknown), with a warning on stderr naming the file, the
// chunk and the bytes missing: what mapconvert and mapdiff read. Too little
// of it is still refused.
TEST(MapFormatBad, CarmenMapCutShortReadsWithAWarning) {
  TempDir dir;
  carmen::MapFile grid_only;  // the gridmap last in the file
  grid_only.gridmap = sample().grid;
  carmen::write_map_file(dir.file("whole.map"), grid_only);
  const std::string whole = read_bytes(dir.file("whole.map"));
  for (const char *name : {"short.map", "short.map.gz"}) {
    const std::string path = dir.file(name);
    if (std::string(name).size() > 9) {
      maptest::gzip_to_file(path, whole.substr(0, whole.size() - 7));
    } else {
      write_bytes(path, whole.substr(0, whole.size() - 7));
    }
    testing::internal::CaptureStderr();
    const carmen::MapRead r = carmen::read_map(path);
    const std::string err = testing::internal::GetCapturedStderr();
    ASSERT_EQ(r.grid.cells.size(), 6u);
    EXPECT_EQ(r.grid.at(0, 0), 0.0f);
    EXPECT_EQ(r.grid.at(1, 0), 1.0f);
    const std::vector<float> want = maptest::cells_cut_short(whole.substr(whole.size() - 8), 1);  // the last 2 cells
    EXPECT_EQ(r.grid.at(2, 0), want[0]);  // one byte of it came, the rest zero as in CARMEN's calloc()ed grid
    EXPECT_EQ(r.grid.at(2, 1), 0.0f);     // 1 - 51/255 there, cut off
    EXPECT_EQ(err.rfind(path + ": warning: the GRIDMAP chunk at byte ", 0), 0u) << err;
    EXPECT_NE(err.find("is 7 bytes short"), std::string::npos) << err;
  }
}

TEST(MapFormatBad, DamagedImagesNameTheFile) {
  TempDir dir;
  carmen::write_map(dir.file("ok.pgm"), sample());
  carmen::write_map(dir.file("ok.png"), sample());
  const std::string png = read_bytes(dir.file("ok.png"));
  write_bytes(dir.file("cut.png"), png.substr(0, png.size() / 2));
  expect_file_error(dir.file("cut.png"), dir.file("cut.png"), "PNG");
  write_bytes(dir.file("junk.png"), "not a png at all");
  expect_file_error(dir.file("junk.png"), dir.file("junk.png"), "PNG");

  const std::string pgm = read_bytes(dir.file("ok.pgm")), yaml = read_bytes(dir.file("ok.yaml"));
  write_bytes(dir.file("cut.pgm"), pgm.substr(0, pgm.size() - 1));
  write_bytes(dir.file("cut.yaml"), yaml);
  expect_file_error(dir.file("cut.pgm"), dir.file("cut.pgm"), "cut short");
  write_bytes(dir.file("huge.pgm"), "P5 99999 99999 255\n");
  write_bytes(dir.file("huge.yaml"), yaml);
  expect_file_error(dir.file("huge.pgm"), dir.file("huge.pgm"), "99999 x 99999");
  write_bytes(dir.file("p2.pgm"), "P2 1 1 255\n0\n");
  write_bytes(dir.file("p2.yaml"), yaml);
  expect_file_error(dir.file("p2.pgm"), dir.file("p2.pgm"), "P5");
  write_bytes(dir.file("noyaml.pgm"), pgm);
  expect_file_error(dir.file("noyaml.pgm"), dir.file("noyaml.yaml"), "cannot open");
  write_bytes(dir.file("badres.pgm"), pgm);
  write_bytes(dir.file("badres.yaml"), "image: badres.pgm\norigin: [0, 0, 0]\nresolution: fast\n");
  expect_file_error(dir.file("badres.pgm"), dir.file("badres.yaml"), "resolution", 3);
  write_bytes(dir.file("nores.pgm"), pgm);
  write_bytes(dir.file("nores.yaml"), "image: nores.pgm\norigin: [0, 0]\nresolution: 0.1\n");
  expect_file_error(dir.file("nores.pgm"), dir.file("nores.yaml"), "origin", 2);
}

// mapdiff's picture: RGB pixels come back as written.
TEST(ImageRgb, RgbPngRoundTrip) {
  TempDir dir;
  const std::vector<uint8_t> rgb = {255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30, 40, 50, 60, 70, 80, 90};
  carmen::write_rgb_png(dir.file("c.png"), 3, 2, rgb);
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&img, dir.file("c.png").c_str()));
  EXPECT_EQ(img.width, 3u);
  EXPECT_EQ(img.height, 2u);
  img.format = PNG_FORMAT_RGB;
  std::vector<uint8_t> back(PNG_IMAGE_SIZE(img));
  ASSERT_TRUE(png_image_finish_read(&img, nullptr, back.data(), 0, nullptr));
  EXPECT_EQ(back, rgb);
  EXPECT_THROW(carmen::write_rgb_png(dir.file("d.png"), 3, 2, {1, 2, 3}), std::invalid_argument);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"c.png"});
}

}  // namespace
