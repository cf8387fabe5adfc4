// carmen_compat/image_io.h: PGM + YAML for map_server, PNG.
#include "carmen_compat/image_io.h"

#include <gtest/gtest.h>
#include <png.h>
#include <zlib.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "carmen_compat/error.h"
#include "carmen_compat/map_format.h"
#include "map_test_support.h"

namespace {

using maptest::read_bytes;
using maptest::TempDir;

// A 4 x 2 map; each value's grey levels are worked out by hand below.
//   y=1 (top row):    0.5   0.0   1.0   0.65f
//   y=0 (bottom row): -1    0.75  0.125 2.5 (off-limits overlay)
carmen::GridMap tiny_map() {
  carmen::GridMap g = carmen::GridMap::filled(4, 2, 0.05);
  g.at(0, 1) = 0.5f;
  g.at(1, 1) = 0.0f;
  g.at(2, 1) = 1.0f;
  g.at(3, 1) = 0.65f;
  g.at(0, 0) = -1.0f;
  g.at(1, 0) = 0.75f;
  g.at(2, 0) = 0.125f;
  g.at(3, 0) = 2.5f;
  return g;
}

// Trinary: > 0.65 black, < 0.196 254, else 205. 0.65f is 0.6499999762 (not
// above 0.65), 0.125 is free, 0.5 in between, 2.5 off-limits -> occupied.
const std::vector<uint8_t> kTrinary = {205, 254, 0, 205, /**/ 205, 0, 254, 0};
// Scale: round(255 (1 - p)): 127.5->128, 255, 0, 89.25->89; unknown 205,
// 63.75->64, 223.125->223, off-limits 0.
const std::vector<uint8_t> kScale = {128, 255, 0, 89, /**/ 205, 64, 223, 0};
// Raw: round(100 p): 50, 0, 100, 64.99999762->65; unknown 255, 75, 12.5->13, 100.
const std::vector<uint8_t> kRaw = {50, 0, 100, 65, /**/ 255, 75, 13, 100};
// PNG (RGB): grey round(255 (1 - p)); unknown -1 (0 below) is #708986.
const std::vector<uint8_t> kPng = {128, 255, 0, 89, /**/ 0, 64, 223, 0};
constexpr uint8_t kUnknownRgb[3] = {0x70, 0x89, 0x86};

struct Pgm {
  std::string magic;
  int width = 0, height = 0, maxval = 0;
  std::vector<uint8_t> pixels;
};

// A strict reader for the header form we write: "P5\nW H\n255\n" + pixels.
Pgm read_pgm(const std::string &path) {
  const std::string raw = read_bytes(path);
  std::istringstream in(raw);
  Pgm p;
  in >> p.magic >> p.width >> p.height >> p.maxval;
  in.get();  // the single whitespace byte before the pixels
  const size_t at = static_cast<size_t>(in.tellg());
  p.pixels.assign(raw.begin() + static_cast<long>(at), raw.end());
  return p;
}

std::map<std::string, std::string> read_yaml(const std::string &path) {
  std::map<std::string, std::string> kv;
  std::istringstream in(read_bytes(path));
  std::string line;
  while (std::getline(in, line)) {
    const size_t colon = line.find(": ");
    if (colon != std::string::npos) kv[line.substr(0, colon)] = line.substr(colon + 2);
  }
  return kv;
}

TEST(MapImagePgm, TrinaryPixelsAndYaml) {
  TempDir dir;
  const std::string pgm = dir.file("tiny.pgm");
  carmen::write_pgm_with_yaml(pgm, tiny_map(), carmen::GlobalOffset{-1.5, 2.25, 0});
  EXPECT_EQ(read_bytes(pgm).substr(0, 11), "P5\n4 2\n255\n");
  const Pgm p = read_pgm(pgm);
  EXPECT_EQ(p.magic, "P5");
  EXPECT_EQ(p.width, 4);
  EXPECT_EQ(p.height, 2);
  EXPECT_EQ(p.maxval, 255);
  EXPECT_EQ(p.pixels, kTrinary);

  const auto yaml = read_yaml(dir.file("tiny.yaml"));
  EXPECT_EQ(yaml.size(), 7u);
  EXPECT_EQ(yaml.at("image"), "tiny.pgm");
  EXPECT_EQ(yaml.at("resolution"), "0.05");
  EXPECT_EQ(yaml.at("origin"), "[-1.5, 2.25, 0]");
  EXPECT_EQ(yaml.at("negate"), "0");
  EXPECT_EQ(yaml.at("occupied_thresh"), "0.65");
  EXPECT_EQ(yaml.at("free_thresh"), "0.196");
  EXPECT_EQ(yaml.at("mode"), "trinary");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"tiny.pgm", "tiny.yaml"}));
}

// Numbers as people write them (issue: ROS conventions): a resolution
// computed as 0.03 / 7 * 7 (not 0.03 in double) and origins with 17 digits
// come out as the shortest text of their nearest float.
TEST(MapImagePgm, YamlNumbersAreTheShortestTextOfTheirFloat) {
  TempDir dir;
  carmen::GridMap m = tiny_map();
  m.resolution = 0.03 / 7 * 7;
  ASSERT_NE(m.resolution, 0.03);  // else this test would not see a long resolution
  carmen::write_pgm_with_yaml(dir.file("n.pgm"), m, carmen::GlobalOffset{-13.499734000000002, 1234.5678901234, 0});
  const auto yaml = read_yaml(dir.file("n.yaml"));
  EXPECT_EQ(yaml.at("resolution"), "0.03");
  EXPECT_EQ(yaml.at("origin"), "[-13.499734, 1234.5679, 0]");  // 1234.5679f is the float nearest 1234.5678901234
}

TEST(MapImagePgm, ScaleAndRawModes) {
  TempDir dir;
  carmen::write_pgm_with_yaml(dir.file("s.pgm"), tiny_map(), {}, carmen::PgmMode::Scale);
  EXPECT_EQ(read_pgm(dir.file("s.pgm")).pixels, kScale);
  EXPECT_EQ(read_yaml(dir.file("s.yaml")).at("mode"), "scale");
  carmen::write_pgm_with_yaml(dir.file("r.pgm"), tiny_map(), {}, carmen::PgmMode::Raw);
  EXPECT_EQ(read_pgm(dir.file("r.pgm")).pixels, kRaw);
  EXPECT_EQ(read_yaml(dir.file("r.yaml")).at("mode"), "raw");
  EXPECT_EQ(read_yaml(dir.file("r.yaml")).at("origin"), "[0, 0, 0]");
}

TEST(MapImagePgm, ModeNames) {
  carmen::PgmMode m = carmen::PgmMode::Trinary;
  EXPECT_TRUE(carmen::parse_pgm_mode("raw", &m));
  EXPECT_EQ(m, carmen::PgmMode::Raw);
  EXPECT_TRUE(carmen::parse_pgm_mode("scale", &m));
  EXPECT_EQ(m, carmen::PgmMode::Scale);
  EXPECT_FALSE(carmen::parse_pgm_mode("Trinary", &m));
  EXPECT_EQ(m, carmen::PgmMode::Scale);
}

TEST(MapImagePgm, FreiburgPixelsFollowTheRule) {
  TempDir dir;
  const std::string src = maptest::map_fixture("freiburg.map");
  const carmen::MapFile m = carmen::read_map_file(src);
  carmen::write_pgm_with_yaml(dir.file("fr.pgm"), *m.gridmap, {});
  const Pgm p = read_pgm(dir.file("fr.pgm"));
  ASSERT_EQ(p.width, 300);
  ASSERT_EQ(p.height, 300);
  ASSERT_EQ(p.pixels.size(), 90000u);
  EXPECT_EQ(read_yaml(dir.file("fr.yaml")).at("resolution"), "0.1");
  // Cell values straight from the file's bytes (after id 17, creator 189,
  // gridmap header 27), x-major; pixel (row 299 - y, column x).
  const std::string raw = read_bytes(src);
  size_t checked_occ = 0, checked_free = 0, checked_unknown = 0;
  for (int x = 0; x < 300; x += 7) {
    for (int y = 0; y < 300; y += 3) {
      const float v = maptest::read_f32(raw, 17 + 189 + 27 + 4 * (size_t(x) * 300 + size_t(y)));
      const uint8_t px = p.pixels[size_t(299 - y) * 300 + size_t(x)];
      if (v == -1.0f) {
        EXPECT_EQ(px, 205);
        ++checked_unknown;
      } else if (v > 0.65) {
        EXPECT_EQ(px, 0);
        ++checked_occ;
      } else if (v < 0.196) {
        EXPECT_EQ(px, 254);
        ++checked_free;
      } else {
        EXPECT_EQ(px, 205);
      }
    }
  }
  EXPECT_GT(checked_occ, 10u);
  EXPECT_GT(checked_free, 100u);
  EXPECT_GT(checked_unknown, 100u);
}

TEST(MapImagePgm, YamlPathNextToThePgm) {
  EXPECT_EQ(carmen::yaml_path_for("a/b.pgm"), "a/b.yaml");
  EXPECT_EQ(carmen::yaml_path_for("x.map.pgm"), "x.map.yaml");
  EXPECT_EQ(carmen::yaml_path_for("dir.v2/image"), "dir.v2/image.yaml");
  EXPECT_EQ(carmen::yaml_path_for("plain"), "plain.yaml");
}

TEST(MapImagePgm, FailuresLeaveNoFiles) {
  TempDir dir;
  try {
    carmen::write_pgm_with_yaml(dir.file("missing/x.pgm"), tiny_map(), {});
    ADD_FAILURE() << "wrote into a missing directory";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), dir.file("missing/x.pgm"));
  }
  carmen::GridMap empty;
  EXPECT_THROW(carmen::write_pgm_with_yaml(dir.file("e.pgm"), empty, {}), std::invalid_argument);
  carmen::GridMap bad = tiny_map();
  bad.cells.pop_back();
  EXPECT_THROW(carmen::write_png(dir.file("b.png"), bad), std::invalid_argument);
  EXPECT_THROW(carmen::write_pgm_with_yaml(dir.file("y.yaml"), tiny_map(), {}), std::invalid_argument);
  EXPECT_TRUE(dir.entries().empty());
}

// ---------------------------------------------------------------------------
// PNG
// ---------------------------------------------------------------------------
TEST(MapImagePng, ReadBackWithLibpng) {
  TempDir dir;
  const std::string path = dir.file("tiny.png");
  carmen::write_png(path, tiny_map());
  const std::string raw = read_bytes(path);
  ASSERT_GT(raw.size(), 33u);
  EXPECT_EQ(raw.substr(0, 8), "\x89PNG\r\n\x1a\n");
  EXPECT_EQ(raw.substr(12, 4), "IHDR");
  EXPECT_EQ(maptest::read_le32(raw, 16), 0x04000000u);  // width 4, big-endian
  EXPECT_EQ(maptest::read_le32(raw, 20), 0x02000000u);  // height 2
  EXPECT_EQ(uint8_t(raw[24]), 8);                       // bit depth
  EXPECT_EQ(uint8_t(raw[25]), 2);                       // colour type 2: RGB, no alpha

  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&image, path.c_str())) << image.message;
  EXPECT_EQ(image.width, 4u);
  EXPECT_EQ(image.height, 2u);
  EXPECT_EQ(image.format, static_cast<png_uint_32>(PNG_FORMAT_RGB));
  image.format = PNG_FORMAT_RGB;
  std::vector<uint8_t> pixels(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr)) << image.message;
  ASSERT_EQ(pixels.size(), 24u);
  for (size_t i = 0; i < 8; ++i) {
    const uint8_t *px = &pixels[3 * i];
    if (i == 4) {  // the unknown cell (0, 0): its own colour
      EXPECT_EQ(std::vector<uint8_t>(px, px + 3), std::vector<uint8_t>(kUnknownRgb, kUnknownRgb + 3));
    } else {
      EXPECT_EQ(std::vector<uint8_t>(px, px + 3), std::vector<uint8_t>(3, kPng[i])) << "pixel " << i;
    }
  }
}

// Unknown and "known, p = 0.5" looked the same (grey 128) in the grey
// pictures; now unknown is a colour no p makes, and reads back as unknown.
TEST(MapImagePng, UnknownHasItsOwnToneNotAnyP) {
  TempDir dir;
  carmen::GridMap g = carmen::GridMap::filled(257, 2, 0.1);
  for (int x = 0; x < 256; ++x) g.at(x, 0) = float(x) / 255.0f;
  g.at(256, 0) = 0.5f;
  for (int x = 0; x < 257; ++x) g.at(x, 1) = carmen::kUnknownCell;
  carmen::write_png(dir.file("t.png"), g);
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&image, dir.file("t.png").c_str())) << image.message;
  image.format = PNG_FORMAT_RGB;
  std::vector<uint8_t> px(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, px.data(), 0, nullptr)) << image.message;
  const uint8_t *unknown = &px[0];  // row 0 is y = 1
  EXPECT_EQ(std::vector<uint8_t>(unknown, unknown + 3), std::vector<uint8_t>(kUnknownRgb, kUnknownRgb + 3));
  for (int x = 0; x < 257; ++x) {
    const uint8_t *known = &px[3 * (257 + size_t(x))];
    EXPECT_EQ(known[0], known[1]);  // every p is a grey: never the unknown colour
    EXPECT_EQ(known[1], known[2]);
  }
  const uint8_t *half = &px[3 * (257 + 256)];
  EXPECT_NE(std::vector<uint8_t>(half, half + 3), std::vector<uint8_t>(unknown, unknown + 3));
  const carmen::GridMap back = carmen::read_png(dir.file("t.png"));
  EXPECT_EQ(back.at(256, 0), 1.0f - 128.0f / 255.0f);
  for (int x = 0; x < 257; ++x) EXPECT_EQ(back.at(x, 1), carmen::kUnknownCell);
}

// A grey picture of the older kind still reads 128 as unknown.
TEST(MapImagePng, OlderGreyPicturesStillRead) {
  TempDir dir;
  const std::vector<uint8_t> grey = {128, 0, 255, 64};
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = 2;
  image.height = 2;
  image.format = PNG_FORMAT_GRAY;
  ASSERT_TRUE(png_image_write_to_file(&image, dir.file("old.png").c_str(), 0, grey.data(), 2, nullptr));
  const carmen::GridMap g = carmen::read_png(dir.file("old.png"));
  EXPECT_EQ(g.at(0, 1), carmen::kUnknownCell);
  EXPECT_EQ(g.at(1, 1), 1.0f);
  EXPECT_EQ(g.at(0, 0), 0.0f);
}

TEST(MapImagePng, FreiburgOrientation) {
  TempDir dir;
  const carmen::MapFile m = carmen::read_map_file(maptest::map_fixture("freiburg.map"));
  const carmen::GridMap &g = *m.gridmap;
  carmen::write_png(dir.file("fr.png"), g);
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&image, dir.file("fr.png").c_str())) << image.message;
  image.format = PNG_FORMAT_RGB;
  std::vector<uint8_t> rgb(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr)) << image.message;
  ASSERT_EQ(rgb.size(), 270000u);
  std::vector<uint8_t> pixels(90000);
  for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = rgb[3 * i];  // red: the grey of a known cell
  size_t checked = 0;
  for (int x = 0; x < 300; x += 5) {
    for (int y = 0; y < 300; y += 5) {
      const float v = g.at(x, y);
      if (v == -1.0f) continue;
      const int expect = static_cast<int>(std::lround(255.0 * (1.0 - double(v))));
      EXPECT_EQ(pixels[size_t(299 - y) * 300 + size_t(x)], expect) << x << "," << y;
      ++checked;
    }
  }
  EXPECT_GT(checked, 500u);
}


// A PGM name with a line break (or quotes, or a colon) cannot add keys to
// the YAML: the image name is a quoted YAML string then.
TEST(MapImagePgm, ANameWithALineBreakCannotInjectKeys) {
  TempDir dir;
  const std::string pgm = dir.file("evil\nnegate: 1.pgm");
  carmen::write_pgm_with_yaml(pgm, tiny_map(), {});
  const std::string yaml = maptest::read_bytes(carmen::yaml_path_for(pgm));
  EXPECT_NE(yaml.find("image: \"evil\\x0anegate: 1.pgm\"\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("\nnegate: 0\n"), std::string::npos) << yaml;
  EXPECT_EQ(yaml.find("\nnegate: 1"), std::string::npos) << yaml;
}

// Two writers of the same PGM and YAML at once: every time, the pair on disk
// comes from one of them (the image's width matches the YAML's resolution).
TEST(MapImagePgm, ConcurrentWritersLeaveAConsistentPair) {
  TempDir dir;
  const std::string pgm = dir.file("shared.pgm");
  carmen::GridMap a = carmen::GridMap::filled(10, 4, 0.1, 0.5f), b = carmen::GridMap::filled(20, 4, 0.2, 0.5f);
  for (int round = 0; round < 100; ++round) {
    std::thread t1([&] { carmen::write_pgm_with_yaml(pgm, a, {}); });
    std::thread t2([&] { carmen::write_pgm_with_yaml(pgm, b, {}); });
    t1.join();
    t2.join();
    const std::string image = maptest::read_bytes(pgm);
    const std::string yaml = maptest::read_bytes(carmen::yaml_path_for(pgm));
    const bool from_a = image.rfind("P5\n10 4\n", 0) == 0;
    ASSERT_NE(yaml.find(from_a ? "resolution: 0.1\n" : "resolution: 0.2\n"), std::string::npos)
        << "round " << round << ": image from " << (from_a ? "a" : "b") << ", yaml:\n" << yaml;
  }
}

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
  EXPECT_EQ(yaml.at("origin"), "[-1.5, 2.25, 0]");
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

// ---------------------------------------------------------------------------
// Hostile and odd inputs
// ---------------------------------------------------------------------------
// What a forked child saw: the error's code and text (or "read" when the
// call returned), how much its peak RSS grew (ru_maxrss) and the seconds the
// call took. The child's address space is capped at `cap_mib` more than it
// starts with (a reader that allocates what a header claims fails there,
// not on the machine), and it is killed after 20 s (a reader that blocks).
struct ChildRun {
  bool ran = false;  // false: the child died or hung
  int code = -1;     // the FileError's code; -1: none thrown
  std::string what;
  long rss_growth_mib = -1;
  double seconds = -1;
};

long vm_bytes() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0;
  statm >> pages;
  return pages * sysconf(_SC_PAGESIZE);
}

template <typename F>
ChildRun run_in_child(long cap_mib, F read) {
  int fds[2];
  if (pipe(fds) != 0) return {};
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    alarm(20);
    const long vm = vm_bytes();
    if (vm > 0) {
      const rlim_t lim = rlim_t(vm) + (rlim_t(cap_mib) << 20);
      const rlimit cap{lim, lim};
      setrlimit(RLIMIT_AS, &cap);
    }
    rusage before{}, after{};
    getrusage(RUSAGE_SELF, &before);
    const auto t0 = std::chrono::steady_clock::now();
    int code = -1;
    std::string what = "read";
    try {
      read();
    } catch (const carmen::FileError &e) {
      code = int(e.code());
      what = e.what();
    } catch (const std::exception &e) {
      what = std::string("not a FileError: ") + e.what();
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    getrusage(RUSAGE_SELF, &after);
    const std::string out = std::to_string(code) + " " + std::to_string((after.ru_maxrss - before.ru_maxrss) / 1024) +
                            " " + std::to_string(secs) + "\n" + what;
    const ssize_t wrote = write(fds[1], out.data(), out.size());
    _exit(wrote == ssize_t(out.size()) ? 0 : 1);
  }
  close(fds[1]);
  std::string got;
  char buf[4096];
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) got.append(buf, size_t(n));
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  ChildRun r;
  const size_t nl = got.find('\n');
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || nl == std::string::npos) return r;
  r.ran = true;
  std::sscanf(got.c_str(), "%d %ld %lf", &r.code, &r.rss_growth_mib, &r.seconds);
  r.what = got.substr(nl + 1);
  return r;
}

std::string be32(uint32_t v) {
  return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
}

std::string png_chunk(const std::string &type, const std::string &data) {
  const std::string body = type + data;
  const uLong crc = crc32(0, reinterpret_cast<const Bytef *>(body.data()), uInt(body.size()));
  return be32(uint32_t(data.size())) + body + be32(uint32_t(crc));
}

// A PNG whose IHDR claims 32767 x 32767 8-bit grey pixels and whose IDAT is
// a few bytes of deflate: under 100 bytes that once made the reader commit
// 4 GiB (4 bytes a pixel, zero-filled) before libpng inflated anything.
std::string huge_png() {
  const std::string ihdr = be32(32767) + be32(32767) + std::string("\x08\x00\x00\x00\x00", 5);
  std::string raw(100, '\0');
  uLongf n = compressBound(uLong(raw.size()));
  std::string idat(n, '\0');
  compress(reinterpret_cast<Bytef *>(&idat[0]), &n, reinterpret_cast<const Bytef *>(raw.data()), uLong(raw.size()));
  idat.resize(n);
  return std::string("\x89PNG\r\n\x1a\n", 8) + png_chunk("IHDR", ihdr) + png_chunk("IDAT", idat) +
         png_chunk("IEND", "");
}

const char kYaml[] = "resolution: 0.05\norigin: [0, 0, 0]\n";

TEST(MapImageLimits, APngClaimingMorePixelsThanItsDataCanHoldIsRefused) {
  TempDir dir;
  const std::string png = dir.file("huge.png");
  maptest::write_bytes(png, huge_png());
  ASSERT_LT(read_bytes(png).size(), 100u);
  maptest::write_bytes(dir.file("huge.yaml"), std::string("image: huge.png\n") + kYaml);
  const auto check = [&](const ChildRun &r) {
    ASSERT_TRUE(r.ran);
    EXPECT_EQ(r.code, int(carmen::ErrorCode::BadInput)) << r.what;
    EXPECT_EQ(r.what.rfind(png + ": ", 0), 0u) << r.what;
    EXPECT_NE(r.what.find("32767 x 32767"), std::string::npos) << r.what;
    EXPECT_NE(r.what.find("more than its compressed data can hold"), std::string::npos) << r.what;
    EXPECT_LT(r.rss_growth_mib, 64) << "nothing the size of the claim may be allocated";
    EXPECT_LT(r.seconds, 5.0);
  };
  check(run_in_child(1024, [&] { carmen::read_png(png); }));
  check(run_in_child(1024, [&] { carmen::read_map_server_yaml(dir.file("huge.yaml")); }));
  check(run_in_child(1024, [&] { carmen::read_image_with_yaml(png, dir.file("huge.yaml")); }));
}

// A 1-bit PNG just over 2^28 pixels: 33 KB of deflated zeros, as much as
// such data compresses, so the deflate-ratio check passes; decoding it would
// take over 1 GiB as RGBA and as a grid. Refused by its declared size against
// the map budget (1 GiB, as a CARMEN map's chunks), before any allocation.
TEST(MapImageLimits, APngBeyondTheMapBudgetIsRefusedBeforeDecoding) {
  TempDir dir;
  const uint32_t w = 16385, h = 16384;  // 2^28 + 2^14 pixels: 4 bytes each is over 1 GiB
  const std::string ihdr = be32(w) + be32(h) + std::string("\x01\x00\x00\x00\x00", 5);  // 1-bit grey
  const std::string raw(size_t(h) * (1 + (w + 7) / 8), '\0');                       // filter byte + row
  uLongf n = compressBound(uLong(raw.size()));
  std::string idat(n, '\0');
  compress2(reinterpret_cast<Bytef *>(&idat[0]), &n, reinterpret_cast<const Bytef *>(raw.data()), uLong(raw.size()), 9);
  idat.resize(n);
  const std::string png = dir.file("wide.png");
  maptest::write_bytes(png, std::string("\x89PNG\r\n\x1a\n", 8) + png_chunk("IHDR", ihdr) + png_chunk("IDAT", idat) +
                                png_chunk("IEND", ""));
  ASSERT_GT(read_bytes(png).size() * 1032, uint64_t(w) * h / 8) << "the deflate-ratio check alone would refuse it";
  maptest::write_bytes(dir.file("wide.yaml"), std::string("image: wide.png\n") + kYaml);
  const auto check = [&](const ChildRun &r) {
    ASSERT_TRUE(r.ran);
    EXPECT_EQ(r.code, int(carmen::ErrorCode::TooLarge)) << r.what;
    EXPECT_EQ(r.what.rfind(png + ": ", 0), 0u) << r.what;
    EXPECT_NE(r.what.find("16385 x 16384"), std::string::npos) << r.what;
    EXPECT_NE(r.what.find("1024 MiB a map may hold"), std::string::npos) << r.what;
    EXPECT_LT(r.rss_growth_mib, 64) << "nothing the size of the image may be allocated";
  };
  check(run_in_child(3072, [&] { carmen::read_png(png); }));
  check(run_in_child(3072, [&] { carmen::read_map_server_yaml(dir.file("wide.yaml")); }));
}

// The bound is deflate's ratio on the file's own pixel format: a real
// uniform map, as compressible as PNGs get, still reads.
TEST(MapImageLimits, AHighlyCompressibleRealPngStillReads) {
  TempDir dir;
  const std::string png = dir.file("flat.png");
  carmen::write_png(png, carmen::GridMap::filled(3000, 2000, 0.05, 0.0f));
  const carmen::GridMap g = carmen::read_png(png);
  EXPECT_EQ(g.size_x, 3000);
  EXPECT_EQ(g.size_y, 2000);
  EXPECT_EQ(g.cells.back(), 0.0f);
}

// An allocation that fails is a FileError naming the image, not a bare
// std::bad_alloc.
TEST(MapImageLimits, RunningOutOfMemoryIsAFileErrorNamingTheImage) {
#if defined(__SANITIZE_ADDRESS__)
  // ASan's allocator dies on an address-space limit instead of throwing
  // std::bad_alloc: the case only exists without it.
  GTEST_SKIP() << "AddressSanitizer ends the process on out of memory instead of throwing";
#endif
  TempDir dir;
  const std::string png = dir.file("big.png");
  carmen::write_png(png, carmen::GridMap::filled(4000, 4000, 0.05, 0.0f));  // 64 MB as RGBA
  const ChildRun r = run_in_child(16, [&] { carmen::read_png(png); });
  ASSERT_TRUE(r.ran);
  EXPECT_EQ(r.code, int(carmen::ErrorCode::OutOfMemory)) << r.what;
  EXPECT_EQ(r.what.rfind(png + ": ", 0), 0u) << r.what;
  EXPECT_NE(r.what.find("out of memory"), std::string::npos) << r.what;
}

// A FIFO as the image (or any file that is not a regular one) is refused,
// not opened: reading it would block mapconvert for ever.
TEST(MapImageLimits, AnImageThatIsNotARegularFileIsRefused) {
  TempDir dir;
  const std::string fifo = dir.file("map.pgm");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  maptest::write_bytes(dir.file("map.yaml"), std::string("image: map.pgm\n") + kYaml);
  for (int which = 0; which < 3; ++which) {
    SCOPED_TRACE(which);
    const ChildRun r = run_in_child(1024, [&] {
      if (which == 0) carmen::read_map_server_yaml(dir.file("map.yaml"));
      if (which == 1) carmen::read_image_with_yaml(fifo, dir.file("map.yaml"));
      if (which == 2) carmen::read_png(fifo);
    });
    ASSERT_TRUE(r.ran) << "the reader blocked on the FIFO";
    EXPECT_EQ(r.code, int(carmen::ErrorCode::Io)) << r.what;
    EXPECT_EQ(r.what, fifo + ": is a FIFO, not a regular file: an image is read whole; give a file");
  }
}

// PGM dimensions beyond INT_MAX: their product is not wrapped into a small
// number (2^32 x 2^32 once came out as 0 pixels, "bad input").
TEST(MapImageLimits, PgmDimensionsBeyondIntAreTooLarge) {
  TempDir dir;
  const std::string pgm = dir.file("wide.pgm");
  maptest::write_bytes(pgm, "P5\n4294967296 4294967296\n255\n" + std::string(16, '\0'));
  maptest::write_bytes(dir.file("wide.yaml"), std::string("image: wide.pgm\n") + kYaml);
  try {
    carmen::read_map_server_yaml(dir.file("wide.yaml"));
    ADD_FAILURE() << "read";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), pgm);
    EXPECT_EQ(e.code(), carmen::ErrorCode::TooLarge) << e.what();
    EXPECT_NE(std::string(e.what()).find("4294967296 x 4294967296"), std::string::npos) << e.what();
  }
  maptest::write_bytes(pgm, "P5\n3000000000 1\n255\n" + std::string(16, '\0'));
  try {
    carmen::read_map_server_yaml(dir.file("wide.yaml"));
    ADD_FAILURE() << "read";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.code(), carmen::ErrorCode::TooLarge) << e.what();
  }
}

// A YAML saved with a UTF-8 byte order mark reads like one without.
TEST(MapImageLimits, AYamlWithAByteOrderMarkReads) {
  TempDir dir;
  carmen::write_pgm_with_yaml(dir.file("m.pgm"), tiny_map(), {});
  maptest::write_bytes(dir.file("bom.yaml"), std::string("\xEF\xBB\xBFimage: m.pgm\n") + kYaml);
  const carmen::PgmMap p = carmen::read_map_server_yaml(dir.file("bom.yaml"));
  EXPECT_EQ(p.grid.size_x, 4);
  EXPECT_EQ(p.grid.size_y, 2);
  EXPECT_EQ(p.grid.resolution, 0.05);
}

}  // namespace
