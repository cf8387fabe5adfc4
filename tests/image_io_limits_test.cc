// carmen_compat/image_io.h on hostile and odd inputs: images that claim
// more than they hold or than the budget allows, running out of memory,
// files that are not regular, sizes beyond int.
#include "carmen_compat/image_io.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

#include "carmen_compat/error.h"
#include "image_io_test_support.h"

namespace {

using namespace imagetest;

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
