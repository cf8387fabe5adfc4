// carmen_compat/image_io.h: PGM + YAML for map_server, PNG. Thresholds and
// map_server's YAML: image_io_yaml_test.cc; hostile and odd inputs:
// image_io_limits_test.cc.
#include "carmen_compat/image_io.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "carmen_compat/error.h"
#include "image_io_test_support.h"

namespace {

using namespace imagetest;

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
  EXPECT_EQ(yaml.at("origin"), "[-1.5, 2.25, 0.0]");
  EXPECT_EQ(yaml.at("negate"), "0");
  EXPECT_EQ(yaml.at("occupied_thresh"), "0.65");
  EXPECT_EQ(yaml.at("free_thresh"), "0.196");
  EXPECT_EQ(yaml.at("mode"), "trinary");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"tiny.pgm", "tiny.yaml"}));
}

// Numbers as people write them (issue: ROS conventions): a resolution
// computed as 0.03 / 7 * 7 (not 0.03 in double) comes out as the shortest
// text of its float; the origin keeps its double's digits, since the .map's
// OFFSET and the tf tree are doubles (a float moves a UTM origin by cells).
TEST(MapImagePgm, YamlResolutionIsItsFloatAndOriginItsDouble) {
  TempDir dir;
  carmen::GridMap m = tiny_map();
  m.resolution = 0.03 / 7 * 7;
  ASSERT_NE(m.resolution, 0.03);  // else this test would not see a long resolution
  carmen::write_pgm_with_yaml(dir.file("n.pgm"), m, carmen::GlobalOffset{-13.499734000000002, 1234.5678901234, 0});
  const auto yaml = read_yaml(dir.file("n.yaml"));
  EXPECT_EQ(yaml.at("resolution"), "0.03");
  EXPECT_EQ(yaml.at("origin"), "[-13.499734000000002, 1234.5678901234, 0.0]");
}

TEST(MapImagePgm, ScaleAndRawModes) {
  TempDir dir;
  carmen::write_pgm_with_yaml(dir.file("s.pgm"), tiny_map(), {}, carmen::PgmMode::Scale);
  EXPECT_EQ(read_pgm(dir.file("s.pgm")).pixels, kScale);
  EXPECT_EQ(read_yaml(dir.file("s.yaml")).at("mode"), "scale");
  carmen::write_pgm_with_yaml(dir.file("r.pgm"), tiny_map(), {}, carmen::PgmMode::Raw);
  EXPECT_EQ(read_pgm(dir.file("r.pgm")).pixels, kRaw);
  EXPECT_EQ(read_yaml(dir.file("r.yaml")).at("mode"), "raw");
  EXPECT_EQ(read_yaml(dir.file("r.yaml")).at("origin"), "[0.0, 0.0, 0.0]");
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
}  // namespace
