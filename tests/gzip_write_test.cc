// The .gz writer (carmen_compat/src/gzip_write.h): what each codec this build
// has (zlib always, ISA-L where it was found) writes, zlib's gzread gives
// back byte for byte (an independent reader: CARMEN's own), in one piece or
// written in parts, empty or past the writer's buffers; a failed write
// names the file and says why.
#include "gzip_write.h"
#include "map_test_support.h"
#include "test_seed.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <random>
#include <string>
#include <vector>

#include "carmen_compat/error.h"

namespace {

using carmen::gzip::Codec;
using carmen::gzip::GzipWriter;
using maptest::gunzip_file;

std::vector<Codec> codecs() {
  std::vector<Codec> out{Codec::ZLIB};
  if (carmen::gzip::codec_available(Codec::ISAL)) out.push_back(Codec::ISAL);
  return out;
}

int open_for_writing(const std::string &path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  EXPECT_GE(fd, 0) << path;
  return fd;
}

// A map-like payload: floats of a smooth field (they compress a little, as
// a map's do) and runs of one value (unknown cells), n bytes.
std::string payload(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::string s;
  s.reserve(n);
  std::uniform_real_distribution<float> noise(0.0f, 1.0f);
  while (s.size() < n) {
    const bool run = rng() % 3 == 0;
    for (int i = 0; i < 4096 && s.size() < n; ++i) {
      const float v = run ? -1.0f : 0.5f + 0.4f * noise(rng);
      s.append(reinterpret_cast<const char *>(&v), std::min<size_t>(sizeof v, n - s.size()));
    }
  }
  return s;
}

void write_in_parts(const std::string &path, const std::string &data, size_t part, Codec codec) {
  GzipWriter w(open_for_writing(path), path, codec);
  for (size_t at = 0; at < data.size(); at += part) w.write(data.data() + at, std::min(part, data.size() - at));
  w.close();
}

TEST(GzipWrite, ZlibReadsBackWhatEachCodecWrote) {
  maptest::TempDir dir;
  const uint32_t seed = vasco::testing_support::test_seed();
  for (Codec codec : codecs()) {
    SCOPED_TRACE(carmen::gzip::codec_name(codec));
    // empty, one byte, a map of fr079's size, and past the 256 KiB output buffer many times over
    for (size_t n : {size_t(0), size_t(1), size_t(409160), size_t(5) << 20}) {
      const std::string data = payload(n, seed + static_cast<uint32_t>(n));
      for (size_t part : {data.size() + 1, size_t(1000), size_t(65536)}) {
        const std::string path = dir.file("out.gz");
        write_in_parts(path, data, part, codec);
        EXPECT_EQ(gunzip_file(path), data) << n << " bytes in parts of " << part;
        const std::string raw = maptest::read_bytes(path);
        ASSERT_GE(raw.size(), 18u);  // a gzip member: header, data, trailer
        EXPECT_EQ(static_cast<unsigned char>(raw[0]), 0x1f);
        EXPECT_EQ(static_cast<unsigned char>(raw[1]), 0x8b);
      }
    }
  }
}

TEST(GzipWrite, AFullDeviceNamesTheFileAndTheReason) {
  for (Codec codec : codecs()) {
    SCOPED_TRACE(carmen::gzip::codec_name(codec));
    const int fd = ::open("/dev/full", O_WRONLY);
    if (fd < 0) GTEST_SKIP() << "no /dev/full here";
    try {
      GzipWriter w(fd, "maps/site.map.gz", codec);
      const std::string data = payload(size_t(2) << 20, 7);
      w.write(data.data(), data.size());
      w.close();
      ADD_FAILURE() << "a write to /dev/full succeeded";
    } catch (const carmen::FileError &e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("maps/site.map.gz"), std::string::npos) << what;
      EXPECT_NE(what.find("No space left"), std::string::npos) << what;
    }
  }
}

}  // namespace
