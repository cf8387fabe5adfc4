// carmen_compat/image_io.h: map_server's thresholds and negate in the YAML
// and the pixels, PNG + YAML, and map_server YAML files read.
#include "carmen_compat/image_io.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cstdio>
#include <string>
#include <vector>

#include "carmen_compat/error.h"
#include "carmen_compat/map_format.h"
#include "image_io_test_support.h"

namespace {

using namespace imagetest;

// ---------------------------------------------------------------------------
// Thresholds, negate, PNG + YAML, reading a map_server YAML
// ---------------------------------------------------------------------------
TEST(MapServerOptions, DefaultsAndLevels) {
  const carmen::MapServerOptions d;
  EXPECT_EQ(d.free_thresh, 0.196);
  EXPECT_EQ(d.occupied_thresh, 0.65);
  const carmen::TrinaryLevels t = carmen::trinary_levels(d);
  EXPECT_EQ(t.occupied, 0);
  EXPECT_EQ(t.free, 254);
  EXPECT_EQ(t.unknown, 205);
  // nav2's free_thresh 0.25: map_server reads 205 as (255 - 205) / 255 =
  // 0.196 < 0.25, free; unknown moves to 191, (255 - 191) / 255 = 0.251.
  carmen::MapServerOptions nav2;
  nav2.free_thresh = 0.25;
  EXPECT_EQ(carmen::trinary_levels(nav2).unknown, 191);
  // A free_thresh at or below 1/255: 254 would not be free, 255 is.
  carmen::MapServerOptions tiny;
  tiny.free_thresh = 0.003;
  EXPECT_EQ(carmen::trinary_levels(tiny).free, 255);
}

TEST(MapServerOptions, ProblemsNameTheSetting) {
  carmen::MapServerOptions o;
  EXPECT_EQ(carmen::map_server_options_problem(o), "");
  o.free_thresh = 0.7;
  EXPECT_NE(carmen::map_server_options_problem(o, "--free-thresh", "--occupied-thresh").find(
                "--free-thresh 0.7 must be below --occupied-thresh 0.65"),
            std::string::npos);
  o.free_thresh = -0.1;
  EXPECT_NE(carmen::map_server_options_problem(o, "--free-thresh").find("--free-thresh -0.1: must be a number from 0 to 1"),
            std::string::npos);
  o = carmen::MapServerOptions{};
  o.occupied_thresh = 1.5;
  EXPECT_NE(carmen::map_server_options_problem(o, "F", "O").find("O 1.5"), std::string::npos);
  o = carmen::MapServerOptions{};
  o.free_thresh = 0.5;
  o.occupied_thresh = 0.501;  // no level v has 0.5 <= (255 - v) / 255 <= 0.501
  EXPECT_NE(carmen::map_server_options_problem(o).find("no grey level"), std::string::npos);
  EXPECT_THROW(carmen::trinary_levels(o), std::invalid_argument);
  o = carmen::MapServerOptions{};
  o.mode = carmen::PgmMode::Raw;
  o.negate = true;
  EXPECT_NE(carmen::map_server_options_problem(o, "F", "O", "--negate").find("--negate"), std::string::npos);
  o.mode = carmen::PgmMode::Scale;
  EXPECT_EQ(carmen::map_server_options_problem(o), "");
}

TEST(MapImagePgm, ThresholdsAndNegateInTheYamlAndTheLevels) {
  TempDir dir;
  carmen::MapToWrite m;
  m.grid = tiny_map();
  m.origin = carmen::GlobalOffset{1, 2, 0};
  m.free_thresh = 0.3;
  m.occupied_thresh = 0.6;
  m.negate = true;
  carmen::write_map(dir.file("t.pgm"), m);
  const auto yaml = read_yaml(dir.file("t.yaml"));
  EXPECT_EQ(yaml.at("free_thresh"), "0.3");
  EXPECT_EQ(yaml.at("occupied_thresh"), "0.6");
  EXPECT_EQ(yaml.at("negate"), "1");
  EXPECT_EQ(yaml.at("mode"), "trinary");
  // Before negation: 0.5 is between, unknown at 178 ((255 - 178) / 255 =
  // 0.302, the level nearest 205 not below 0.3); 0.65f > 0.6 occupied; 0.125
  // free 254. Negated: 255 - level.
  const std::vector<uint8_t> want = {77, 1, 255, 255, /**/ 77, 255, 1, 255};
  EXPECT_EQ(read_pgm(dir.file("t.pgm")).pixels, want);
  // map_server, negate 1: occupancy v / 255; 77 -> 0.302 unknown, 1 -> free, 255 -> occupied.
  const carmen::MapRead r = carmen::read_map(dir.file("t.pgm"));
  const std::vector<float> cells = {-1, -1, 1, 0, 0, 1, 1, 1};  // x-major: (x, 0) then (x, 1)
  EXPECT_EQ(r.grid.cells, cells);
}

// What map_server does with 205 under nav2's free_thresh 0.25: free.
TEST(MapImagePgm, ReaderFollowsTheYamlThresholds) {
  TempDir dir;
  maptest::write_bytes(dir.file("n.pgm"), std::string("P5\n3 1\n255\n") + char(205) + char(0) + char(254));
  maptest::write_bytes(dir.file("n.yaml"),
                       "image: n.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
                       "occupied_thresh: 0.65\nfree_thresh: 0.25\n");
  const carmen::PgmMap p = carmen::read_map_server_yaml(dir.file("n.yaml"));
  EXPECT_EQ(p.grid.cells, (std::vector<float>{0.0f, 1.0f, 0.0f}));
  EXPECT_EQ(p.options.free_thresh, 0.25);
}

TEST(MapImagePngYaml, ScaleModeHasTransparentUnknown) {
  TempDir dir;
  carmen::MapToWrite m;
  m.grid = tiny_map();
  m.origin = carmen::GlobalOffset{-1.5, 2.25, 0};
  m.pgm_mode = carmen::PgmMode::Scale;
  EXPECT_EQ(carmen::map_output_files(dir.file("s.png+yaml")),
            (std::vector<std::string>{dir.file("s.png"), dir.file("s.yaml")}));
  carmen::write_map(dir.file("s.png+yaml"), m);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"s.png", "s.yaml"}));
  const auto yaml = read_yaml(dir.file("s.yaml"));
  EXPECT_EQ(yaml.at("image"), "s.png");
  EXPECT_EQ(yaml.at("mode"), "scale");
  EXPECT_EQ(yaml.at("origin"), "[-1.5, 2.25, 0.0]");
  // Decoded by libpng, not by our reader: grey + alpha.
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&image, dir.file("s.png").c_str())) << image.message;
  EXPECT_EQ(image.format, static_cast<png_uint_32>(PNG_FORMAT_GA));
  image.format = PNG_FORMAT_GA;
  std::vector<uint8_t> ga(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, ga.data(), 0, nullptr)) << image.message;
  ASSERT_EQ(ga.size(), 16u);
  for (size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(ga[2 * i + 1], i == 4 ? 0 : 255) << "alpha of pixel " << i;
    if (i != 4) EXPECT_EQ(ga[2 * i], kScale[i]) << "grey of pixel " << i;
  }
  // Read back (as .png+yaml and through the YAML): unknown stays unknown.
  for (const std::string &path : {dir.file("s.png+yaml"), dir.file("s.yaml")}) {
    const carmen::MapRead r = carmen::read_map(path);
    ASSERT_EQ(r.grid.cells.size(), 8u) << path;
    EXPECT_EQ(r.grid.at(0, 0), carmen::kUnknownCell) << path;
    EXPECT_NEAR(r.grid.at(1, 0), 0.75, 0.5 / 255) << path;
    EXPECT_NEAR(r.grid.at(0, 1), 0.5, 0.5 / 255) << path;
    ASSERT_TRUE(r.origin);
    EXPECT_EQ(r.origin->x, -1.5);
  }
}

TEST(MapImagePngYaml, TrinaryPngIsGreyWithoutAlpha) {
  TempDir dir;
  carmen::MapToWrite m;
  m.grid = tiny_map();
  carmen::write_map(dir.file("t.png+yaml"), m);
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&image, dir.file("t.png").c_str())) << image.message;
  EXPECT_EQ(image.format, static_cast<png_uint_32>(PNG_FORMAT_GRAY));
  image.format = PNG_FORMAT_GRAY;
  std::vector<uint8_t> grey(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, grey.data(), 0, nullptr)) << image.message;
  EXPECT_EQ(grey, kTrinary);
}

TEST(MapServerYaml, ImageKeyQuotedRelativeOrAbsolute) {
  TempDir dir;
  ASSERT_EQ(::mkdir(dir.file("maps").c_str(), 0755), 0);
  carmen::write_pgm_with_yaml(dir.file("maps/a b.pgm"), tiny_map(), carmen::GlobalOffset{3, 4, 0});
  const std::string yaml = read_bytes(dir.file("maps/a b.yaml"));
  EXPECT_NE(yaml.find("image: \"a b.pgm\"\n"), std::string::npos) << yaml;
  const carmen::PgmMap p = carmen::read_map_server_yaml(dir.file("maps/a b.yaml"));
  EXPECT_EQ(p.image_path, dir.file("maps/a b.pgm"));
  EXPECT_EQ(p.origin.x, 3);
  EXPECT_EQ(p.grid.at(1, 0), 1.0f);
  // An absolute image path and single quotes, as other tools write them.
  maptest::write_bytes(dir.file("abs.yaml"), "# a comment\nimage: '" + dir.file("maps/a b.pgm") +
                                                 "'\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n");
  EXPECT_EQ(carmen::read_map_server_yaml(dir.file("abs.yaml")).grid.cells, p.grid.cells);
}

TEST(MapServerYaml, ErrorsNameTheFileAndLine) {
  TempDir dir;
  carmen::write_pgm_with_yaml(dir.file("m.pgm"), tiny_map(), {});
  const auto error_of = [](const std::string &yaml) -> carmen::FileError {
    try {
      carmen::read_map_server_yaml(yaml);
    } catch (const carmen::FileError &e) {
      return e;
    }
    ADD_FAILURE() << yaml << " was read";
    return carmen::FileError(yaml, "none");
  };
  maptest::write_bytes(dir.file("missing.yaml"), "resolution: 0.05\norigin: [0, 0, 0]\nimage: gone.pgm\n");
  carmen::FileError e = error_of(dir.file("missing.yaml"));
  EXPECT_EQ(e.file(), dir.file("missing.yaml"));
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(std::string(e.what()).find("gone.pgm"), std::string::npos) << e.what();
  maptest::write_bytes(dir.file("bad.yaml"), "image: m.pgm\nresolution: fine\norigin: [0, 0, 0]\n");
  e = error_of(dir.file("bad.yaml"));
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
  maptest::write_bytes(dir.file("noimage.yaml"), "resolution: 0.05\norigin: [0, 0, 0]\n");
  EXPECT_NE(std::string(error_of(dir.file("noimage.yaml")).what()).find("\"image\""), std::string::npos);
  maptest::write_bytes(dir.file("thresh.yaml"),
                       "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nfree_thresh: 0.9\n");
  EXPECT_EQ(error_of(dir.file("thresh.yaml")).line(), 4);
  maptest::write_bytes(dir.file("quote.yaml"), "image: \"m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n");
  EXPECT_EQ(error_of(dir.file("quote.yaml")).line(), 1);
  // An image that is no PGM or PNG, and one cut short.
  maptest::write_bytes(dir.file("j.jpg"), "\xff\xd8\xff\xe0 not a map");
  maptest::write_bytes(dir.file("j.yaml"), "image: j.jpg\nresolution: 0.05\norigin: [0, 0, 0]\n");
  e = error_of(dir.file("j.yaml"));
  EXPECT_EQ(e.file(), dir.file("j.jpg"));
  maptest::write_bytes(dir.file("short.pgm"), "P5\n4 2\n255\nabc");
  maptest::write_bytes(dir.file("short.yaml"), "image: short.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n");
  e = error_of(dir.file("short.yaml"));
  EXPECT_EQ(e.file(), dir.file("short.pgm"));
  EXPECT_NE(std::string(e.what()).find("cut short"), std::string::npos) << e.what();
}
}  // namespace
