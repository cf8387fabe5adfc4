// carmen_compat/image_io.h: PGM + YAML for map_server, PNG.
#include "carmen_compat/image_io.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cmath>
#include <map>
#include <sstream>
#include <thread>

#include "carmen_compat/error.h"
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
// PNG: round(255 (1 - p)), unknown 128.
const std::vector<uint8_t> kPng = {128, 255, 0, 89, /**/ 128, 64, 223, 0};

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
  EXPECT_EQ(uint8_t(raw[25]), 0);                       // colour type 0: grey, no alpha

  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&image, path.c_str())) << image.message;
  EXPECT_EQ(image.width, 4u);
  EXPECT_EQ(image.height, 2u);
  EXPECT_EQ(image.format, static_cast<png_uint_32>(PNG_FORMAT_GRAY));
  image.format = PNG_FORMAT_GRAY;
  std::vector<uint8_t> pixels(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr)) << image.message;
  EXPECT_EQ(pixels, kPng);
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
  image.format = PNG_FORMAT_GRAY;
  std::vector<uint8_t> pixels(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr)) << image.message;
  ASSERT_EQ(pixels.size(), 90000u);
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
