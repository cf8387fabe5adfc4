// carmen_stdio: CARMEN's FILE wrapper, gzip by name.
#include "carmen/carmen_stdio.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "map_test_support.h"

namespace {

using maptest::TempDir;

// The first two bytes of a gzip member.
bool looks_gzipped(const std::string &path) {
  const std::string b = maptest::read_bytes(path);
  return b.size() >= 2 && static_cast<unsigned char>(b[0]) == 0x1f && static_cast<unsigned char>(b[1]) == 0x8b;
}

void write_and_read_back(const std::string &path) {
  carmen_FILE *w = carmen_fopen(path.c_str(), "w");
  ASSERT_NE(w, nullptr) << path;
  carmen_fprintf(w, "line %d %s\n", 1, "one");  // void, as CARMEN's
  EXPECT_EQ(carmen_ferror(w), 0);
  EXPECT_EQ(carmen_fputc('x', w), 'x');
  const char bytes[4] = {'\n', 'a', 'b', '\n'};
  EXPECT_EQ(carmen_fwrite(bytes, 1, 4, w), 4u);
  EXPECT_EQ(carmen_fflush(w), 0);
  EXPECT_EQ(carmen_fclose(w), 0);

  carmen_FILE *r = carmen_fopen(path.c_str(), "r");
  ASSERT_NE(r, nullptr);
  char buf[64];
  ASSERT_NE(carmen_fgets(buf, sizeof buf, r), nullptr);
  EXPECT_STREQ(buf, "line 1 one\n");
  EXPECT_EQ(carmen_ftell(r), 11);
  EXPECT_EQ(carmen_fgetc(r), 'x');
  char rest[8] = {0};
  EXPECT_EQ(carmen_fread(rest, 1, 8, r), 4u);
  EXPECT_EQ(std::memcmp(rest, bytes, 4), 0);
  EXPECT_NE(carmen_feof(r), 0);
  EXPECT_EQ(carmen_ferror(r), 0);
  // Back to the start.
  EXPECT_EQ(carmen_fseek(r, 5, SEEK_SET), 0);
  EXPECT_EQ(carmen_fgetc(r), '1');
  EXPECT_EQ(carmen_fclose(r), 0);
}

TEST(CarmenStdio, PlainRoundTrip) {
  TempDir dir;
  write_and_read_back(dir.file("a.txt"));
  EXPECT_FALSE(looks_gzipped(dir.file("a.txt")));
  EXPECT_EQ(maptest::read_bytes(dir.file("a.txt")), "line 1 one\nx\nab\n");
}

TEST(CarmenStdio, GzipIffTheNameEndsInGz) {
  TempDir dir;
  write_and_read_back(dir.file("a.txt.gz"));
  EXPECT_TRUE(looks_gzipped(dir.file("a.txt.gz")));
  // Independent check with zlib itself.
  gzFile g = gzopen(dir.file("a.txt.gz").c_str(), "rb");
  ASSERT_NE(g, nullptr);
  char buf[64] = {0};
  EXPECT_EQ(gzread(g, buf, sizeof buf - 1), 16);
  gzclose(g);
  EXPECT_STREQ(buf, "line 1 one\nx\nab\n");
}

TEST(CarmenStdio, MissingFileAndBadArguments) {
  TempDir dir;
  EXPECT_EQ(carmen_fopen(dir.file("none.log").c_str(), "r"), nullptr);
  EXPECT_EQ(carmen_fopen(dir.file("none.log.gz").c_str(), "r"), nullptr);
  EXPECT_EQ(carmen_fopen(nullptr, "r"), nullptr);
  EXPECT_EQ(carmen_fclose(nullptr), EOF);
}

TEST(CarmenStdio, CorruptGzipIsReportedByFerror) {
  TempDir dir;
  const std::string path = dir.file("bad.log.gz");
  {
    gzFile g = gzopen(path.c_str(), "wb");
    ASSERT_NE(g, nullptr);
    std::string text(100000, 'a');
    gzwrite(g, text.data(), static_cast<unsigned>(text.size()));
    gzclose(g);
  }
  std::string bytes = maptest::read_bytes(path);
  bytes[bytes.size() / 2] ^= 0x5a;  // damage the deflate stream
  std::FILE *f = std::fopen(path.c_str(), "wb");
  std::fwrite(bytes.data(), 1, bytes.size(), f);
  std::fclose(f);
  carmen_FILE *r = carmen_fopen(path.c_str(), "r");
  ASSERT_NE(r, nullptr);
  char buf[4096];
  while (carmen_fread(buf, 1, sizeof buf, r) > 0) {
  }
  EXPECT_NE(carmen_ferror(r), 0);
  carmen_fclose(r);
}

}  // namespace
