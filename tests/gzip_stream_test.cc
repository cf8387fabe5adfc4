// The log reader's gzip inflater (carmen_compat/src/gzip_stream.h): every
// codec this build has (zlib always, ISA-L where it was found) gives zlib's
// bytes on good files, and zlib's bytes and verdict on damaged ones.
#include "gzip_stream.h"
#include "map_test_support.h"
#include "test_seed.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace {

using carmen::gzip::Codec;
using carmen::gzip::GzipInflater;
using maptest::gunzip_file;
using maptest::read_bytes;

std::string data_log(const std::string &name) {
  return std::string(VASCO_TEST_DATA_DIR) + "/logs/" + name;
}
std::string bundled_log(const std::string &name) {
  return std::string(VASCO_LOGS_DIR) + "/" + name;
}

std::vector<Codec> codecs() {
  std::vector<Codec> out{Codec::ZLIB};
  if (carmen::gzip::codec_available(Codec::ISAL)) out.push_back(Codec::ISAL);
  return out;
}

struct Result {
  std::string bytes;
  bool eof = false;
  std::string error;
};

constexpr std::size_t kChunk = std::size_t(256) << 10;  // what the reader asks for

// Everything a GzipInflater makes of `file`, asked for `chunk` bytes at a
// time, reading in_chunk compressed bytes at a time.
Result inflate_all(std::FILE *file, Codec codec, std::size_t chunk, std::size_t in_chunk = kChunk) {
  Result r;
  GzipInflater inflater(file, codec, in_chunk);
  std::vector<char> buf(chunk);
  for (;;) {
    const std::size_t n = inflater.read(buf.data(), buf.size(), &r.eof, &r.error);
    r.bytes.append(buf.data(), n);
    if (n < buf.size()) break;
  }
  return r;
}
Result inflate_file(const std::string &path, Codec codec, std::size_t chunk = kChunk) {
  std::FILE *f = std::fopen(path.c_str(), "rb");
  if (!f) return Result{"", false, "cannot open " + path};
  Result r = inflate_all(f, codec, chunk);
  std::fclose(f);
  return r;
}
// The same of gzip data in memory (through a temporary file: seekable, as a log is).
Result inflate_bytes(const std::string &gz, Codec codec, std::size_t chunk = kChunk,
                     std::size_t in_chunk = kChunk) {
  std::FILE *f = std::tmpfile();
  if (!f) return Result{"", false, "no temporary file"};
  std::fwrite(gz.data(), 1, gz.size(), f);
  std::rewind(f);
  Result r = inflate_all(f, codec, chunk, in_chunk);
  std::fclose(f);
  return r;
}

// One gzip member of `text`; with `fields`, its header carries a name, a
// comment, an extra field and a header CRC (gzip -N and others write some).
std::string gzip_member(const std::string &text, int level, bool fields) {
  z_stream zs{};
  EXPECT_EQ(deflateInit2(&zs, level, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
  char name[] = "part.log", comment[] = "a member";
  unsigned char extra[] = {'V', 'G', 2, 0, 'h', 'i'};
  gz_header header{};
  if (fields) {
    header.name = reinterpret_cast<Bytef *>(name);
    header.comment = reinterpret_cast<Bytef *>(comment);
    header.extra = extra;
    header.extra_len = sizeof extra;
    header.hcrc = 1;
    deflateSetHeader(&zs, &header);
  }
  std::string out(deflateBound(&zs, static_cast<uLong>(text.size())) + 64, '\0');
  zs.next_in = reinterpret_cast<Bytef *>(const_cast<char *>(text.data()));
  zs.avail_in = static_cast<uInt>(text.size());
  zs.next_out = reinterpret_cast<Bytef *>(&out[0]);
  zs.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(deflate(&zs, Z_FINISH), Z_STREAM_END);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

std::string describe(const Result &r) {
  return std::to_string(r.bytes.size()) + " bytes, " + (r.eof ? "eof" : "error '" + r.error + "'");
}

TEST(GzipStream, BundledLogsInflateToZlibsBytes) {
  for (const char *name : {"intel.gfs.log.gz", "fr079-complete.gfs.log.gz"}) {
    const std::string path = bundled_log(name), want = gunzip_file(path);
    ASSERT_GT(want.size(), 100000u) << path;
    for (Codec c : codecs()) {
      SCOPED_TRACE(std::string(name) + " with " + carmen::gzip::codec_name(c));
      const Result r = inflate_file(path, c);
      EXPECT_TRUE(r.eof) << describe(r);
      EXPECT_TRUE(r.bytes == want) << describe(r);
    }
  }
}

// Members one after another, some with every optional header field, zero
// padding between them (some of it longer than one read of the file), and
// reads of odd sizes: every codec gives the text back.
// `text` cut into gzip members of up to max_len bytes, at random levels, half
// of them with every optional header field, with zero padding between some
// (some of it longer than one read of the file) and after the last.
std::string members_of(const std::string &text, std::size_t max_len, std::mt19937 &rng) {
  std::string gz;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t len = std::min<std::size_t>(text.size() - at, 1 + rng() % max_len);
    gz += gzip_member(text.substr(at, len), static_cast<int>(rng() % 10), rng() % 2 == 0);
    at += len;
    const int pad = static_cast<int>(rng() % 4);
    if (pad == 1) gz += std::string(1 + rng() % 100, '\0');
    if (pad == 2) gz += std::string(300 << 10, '\0');
  }
  return gz + std::string(7, '\0');
}

// Members one after another and reads of odd sizes (down to a byte at a
// time, of text or of gzip data): every codec gives the text back.
TEST(GzipStream, MembersPaddingAndHeaderFields) {
  const std::string text = gunzip_file(bundled_log("intel.gfs.log.gz"));
  ASSERT_GT(text.size(), 1000000u);
  std::mt19937 rng(vasco::testing_support::test_seed(11));
  const std::string gz = members_of(text, 400000, rng);
  const std::string small_text = text.substr(0, 150000);
  const std::string small_gz = members_of(small_text, 40000, rng);
  for (Codec c : codecs()) {
    for (std::size_t chunk : {std::size_t(1) << 18, std::size_t(777), std::size_t(1)}) {
      SCOPED_TRACE(std::string(carmen::gzip::codec_name(c)) + ", reads of " +
                   std::to_string(chunk));
      const std::string &want = chunk == 1 ? small_text : text;
      const Result r = inflate_bytes(chunk == 1 ? small_gz : gz, c, chunk);
      EXPECT_TRUE(r.eof) << describe(r);
      EXPECT_TRUE(r.bytes == want) << describe(r);
    }
    for (std::size_t in_chunk : {1, 2, 3, 7, 10, 13, 4096}) {
      SCOPED_TRACE(std::string(carmen::gzip::codec_name(c)) + ", gzip data read " +
                   std::to_string(in_chunk) + " bytes at a time");
      const Result r = inflate_bytes(small_gz, c, kChunk, in_chunk);
      EXPECT_TRUE(r.eof) << describe(r);
      EXPECT_TRUE(r.bytes == small_text) << describe(r);
    }
  }
}

// ISA-L writes bytes past some faults before it reports them, and names fewer
// kinds of fault; the inflater decodes such a member again with zlib, so the
// damaged files of the test data, and random damage, read the same with both.
TEST(GzipStream, DamagedFilesGiveZlibsBytesAndVerdict) {
  if (!carmen::gzip::codec_available(Codec::ISAL)) GTEST_SKIP() << "this build has zlib only";
  for (const char *name : {"corrupt.log.gz", "bad_crc.log.gz", "trailing_garbage.log.gz",
                           "truncated.log.gz", "two_members.log.gz", "empty.log.gz",
                           "binary_garbage.log.gz"}) {
    SCOPED_TRACE(name);
    const Result z = inflate_file(data_log(name), Codec::ZLIB);
    const Result i = inflate_file(data_log(name), Codec::ISAL);
    EXPECT_EQ(i.error, z.error);
    EXPECT_EQ(i.eof, z.eof);
    EXPECT_TRUE(i.bytes == z.bytes) << "ISA-L: " << describe(i) << "; zlib: " << describe(z);
  }
  EXPECT_EQ(inflate_file(data_log("corrupt.log.gz"), Codec::ISAL).error,
            "corrupt gzip stream after 19032 uncompressed bytes: invalid distance too far back");

  const std::string gz = read_bytes(bundled_log("intel.gfs.log.gz"));
  ASSERT_GT(gz.size(), 100000u);
  std::mt19937 rng(vasco::testing_support::test_seed(21));
  int faults = 0;
  for (int it = 0; it < 80; ++it) {
    std::string bad = gz;
    const int kind = static_cast<int>(rng() % 3);
    if (kind == 0) bad[10 + rng() % (bad.size() - 10)] ^= static_cast<char>(1 + rng() % 255);
    if (kind == 1) bad.resize(10 + rng() % (bad.size() - 10));
    if (kind == 2) bad.insert(10 + rng() % (bad.size() - 10), std::string(1 + rng() % 40, '\x5a'));
    const std::size_t chunk = rng() % 2 ? kChunk : 1000 + rng() % 5000;
    const std::size_t in_chunk = rng() % 2 ? kChunk : 100 + rng() % 5000;
    const Result z = inflate_bytes(bad, Codec::ZLIB, chunk, in_chunk);
    const Result i = inflate_bytes(bad, Codec::ISAL, chunk, in_chunk);
    ASSERT_EQ(i.error, z.error) << "case " << it;
    ASSERT_TRUE(i.bytes == z.bytes)
        << "case " << it << ": ISA-L " << describe(i) << "; zlib " << describe(z);
    faults += !z.error.empty();
  }
  EXPECT_GT(faults, 50);
}

// zlib refuses a header that sets reserved flag bits, ISA-L would ignore
// them: both refuse it here, as the first member or after a good one.
TEST(GzipStream, ReservedHeaderFlagsAreRefused) {
  const std::string text = "ODOM 1 2 3 0 0 0 1 h 1\n";
  std::string bad = gzip_member(text, 6, false);
  bad[3] = static_cast<char>(bad[3] | 0x20);
  for (Codec c : codecs()) {
    SCOPED_TRACE(carmen::gzip::codec_name(c));
    const Result first = inflate_bytes(bad, c);
    EXPECT_EQ(first.error,
              "corrupt gzip stream after 0 uncompressed bytes: unknown header flags set");
    EXPECT_EQ(first.bytes, "");
    const Result second = inflate_bytes(gzip_member(text, 6, false) + bad, c);
    EXPECT_EQ(second.error,
              "corrupt gzip file: data after the end of the gzip stream is not gzip data");
    EXPECT_EQ(second.bytes, text);
  }
}

// Where the file cannot seek back (a pipe), ISA-L's own verdict on damage
// stands: still an error, never a short read taken for the end.
TEST(GzipStream, DamageThroughAPipeIsStillAnError) {
  for (Codec c : codecs()) {
    SCOPED_TRACE(carmen::gzip::codec_name(c));
    std::FILE *pipe = popen(("cat '" + data_log("corrupt.log.gz") + "'").c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    const Result r = inflate_all(pipe, c, kChunk);
    pclose(pipe);
    EXPECT_FALSE(r.eof);
    EXPECT_EQ(r.error.rfind("corrupt gzip stream after ", 0), 0u) << r.error;
    EXPECT_GE(r.bytes.size(), 19032u);
  }
}

}  // namespace
