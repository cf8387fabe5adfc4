// A map of many named GRIDMAP chunks that compress to almost nothing: with
// NamedChunkReading::Index the reader keeps none of their cells, so reading
// the file for a summary (mapconvert --info) needs memory for one grid, and
// any one named chunk can still be read when asked.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdio>
#include <string>
#include <vector>

#include "carmen_compat/error.h"
#include "carmen_compat/map_file.h"
#include "map_test_support.h"

namespace {

using maptest::chunk;
using maptest::f32;
using maptest::i32;

constexpr int kChunks = 2000;
constexpr int kSide = 128;  // 64 KiB of cells a chunk: 125 MiB of cells in all

// One gzip member of `data`. A gzip file may be a run of members (RFC 1952),
// so the shared cell payload is compressed once and repeated.
std::string gzip_member(const std::string &data) {
  z_stream z{};
  EXPECT_EQ(deflateInit2(&z, 9, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out(deflateBound(&z, data.size()), '\0');
  z.next_in = reinterpret_cast<Bytef *>(const_cast<char *>(data.data()));
  z.avail_in = static_cast<uInt>(data.size());
  z.next_out = reinterpret_cast<Bytef *>(&out[0]);
  z.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

// A main 4 x 4 grid, then kChunks named kSide x kSide grids of 0.5.
std::string many_named_gridmaps_gz() {
  const std::string grid_header = i32(kSide) + i32(kSide) + f32(0.1f);
  std::string cells;
  for (int i = 0; i < kSide * kSide; ++i) cells += f32(0.5f);
  std::string main_payload = i32(4) + i32(4) + f32(0.1f);
  for (int i = 0; i < 16; ++i) main_payload += f32(-1.0f);
  std::string out = gzip_member(maptest::kId + chunk(1, "GRIDMAP", main_payload));
  const std::string cells_gz = gzip_member(cells);
  for (int k = 0; k < kChunks; ++k) {
    const std::string whole = chunk(1, "GRIDMAP", grid_header + cells, "floor" + std::to_string(k), true);
    out += gzip_member(whole.substr(0, whole.size() - cells.size())) + cells_gz;
  }
  return out;
}

long max_rss_kib() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss;
}

// Peak RSS growth (KiB) of reading `path` with `reading`, measured in a
// forked child: the child's high-water mark starts at its RSS at the fork,
// so the growth is what this read added, not what earlier tests left behind.
long rss_growth_of_read(const std::string &path, carmen::NamedChunkReading reading) {
  int fds[2];
  EXPECT_EQ(pipe(fds), 0);
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const long before = max_rss_kib();
    carmen::MapReadOptions opts;
    opts.named_chunks = reading;
    long growth = -1;
    try {
      const carmen::MapFile m = carmen::read_map_file(path, opts);
      growth = max_rss_kib() - before;
    } catch (...) {
    }
    (void)!write(fds[1], &growth, sizeof growth);
    _exit(0);
  }
  close(fds[1]);
  long growth = -1;
  EXPECT_EQ(read(fds[0], &growth, sizeof growth), ssize_t(sizeof growth));
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  return growth;
}

class ManyNamedChunks : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new maptest::TempDir;
    maptest::write_bytes(path(), many_named_gridmaps_gz());
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::string path() { return dir_->file("many.map.gz"); }
  static maptest::TempDir *dir_;
};
maptest::TempDir *ManyNamedChunks::dir_ = nullptr;

TEST_F(ManyNamedChunks, TheFileIsSmall) {
  EXPECT_LT(maptest::read_bytes(path()).size(), 2u << 20);  // like the 1.5 MB file of the report
}

TEST_F(ManyNamedChunks, IndexListsEveryChunkAndKeepsNoCells) {
  carmen::MapReadOptions opts;
  opts.named_chunks = carmen::NamedChunkReading::Index;
  const carmen::MapFile m = carmen::read_map_file(path(), opts);
  ASSERT_TRUE(m.gridmap);
  EXPECT_EQ(m.gridmap->size_x, 4);
  EXPECT_TRUE(m.named.empty());
  EXPECT_EQ(m.unknown_chunks, 0);
  ASSERT_EQ(m.chunks.size(), size_t(kChunks) + 1);
  EXPECT_EQ(m.chunks[1].name, "floor0");
  EXPECT_TRUE(m.chunks[kChunks].deferred);
  EXPECT_FALSE(m.chunks[0].deferred);
  // A deferred chunk is read when asked.
  const carmen::NamedChunk last = carmen::read_named_chunk(path(), m.chunks[kChunks]);
  EXPECT_EQ(last.name, "floor" + std::to_string(kChunks - 1));
  const auto &g = std::get<carmen::GridMap>(last.payload);
  EXPECT_EQ(g.size_x, kSide);
  EXPECT_EQ(g.at(kSide - 1, kSide - 1), 0.5f);
  // The listing of another file's chunk does not match here.
  carmen::ChunkInfo wrong = m.chunks[kChunks];
  wrong.name = "elsewhere";
  EXPECT_THROW(carmen::read_named_chunk(path(), wrong), carmen::FileError);
}

// The bound: the index of 2000 chunks and one 4 x 4 grid need well under
// 16 MiB beyond the reader's buffers; parsing every named chunk keeps their
// 125 MiB of cells (the control: the measurement sees that growth).
TEST_F(ManyNamedChunks, IndexReadingStaysWithinABoundParsingDoesNot) {
  const long index_kib = rss_growth_of_read(path(), carmen::NamedChunkReading::Index);
  const long parse_kib = rss_growth_of_read(path(), carmen::NamedChunkReading::Parse);
  ASSERT_GE(index_kib, 0);
  ASSERT_GE(parse_kib, 0);
  EXPECT_LT(index_kib, 16 * 1024) << "index reading grew the RSS by " << index_kib << " KiB";
  EXPECT_GT(parse_kib, 100 * 1024) << "parsing grew the RSS by only " << parse_kib << " KiB";
}

// mapconvert --info reads the file that way: its peak RSS stays far below
// the 125 MiB of named cells (it was 544 MB for such a file), and it still
// lists every chunk. A control: converting the same file parses them all.
long peak_rss_kib_of(const std::vector<std::string> &args) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char *> argv;
    for (const std::string &a : args) argv.push_back(const_cast<char *>(a.c_str()));
    argv.push_back(nullptr);
    if (freopen("/dev/null", "w", stdout) == nullptr) _exit(126);
    execv(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  struct rusage ru {};
  if (wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1;
  return ru.ru_maxrss;
}

TEST_F(ManyNamedChunks, MapconvertInfoListsEveryChunkWithoutParsingThem) {
  const std::string tool = std::string(VASCO_BIN_DIR) + "/mapconvert";
  const long info_kib = peak_rss_kib_of({tool, "--info", path()});
  ASSERT_GT(info_kib, 0) << "mapconvert --info failed";
  const long convert_kib = peak_rss_kib_of({tool, path(), dir_->file("copy.map")});
  ASSERT_GT(convert_kib, 0) << "mapconvert to .map failed";
  // Both processes carry the same base (libraries, buffers; under ASan its
  // shadow and quarantine too): parsing the 125 MiB of named cells must cost
  // most of them beyond what --info costs.
  EXPECT_GT(convert_kib - info_kib, 100 * 1024) << "--info " << info_kib << " KiB, converting " << convert_kib;
#if !defined(__SANITIZE_ADDRESS__)
  EXPECT_LT(info_kib, 48 * 1024) << "mapconvert --info peaked at " << info_kib << " KiB";
#endif
  FILE *p = popen(("'" + tool + "' --info '" + path() + "'").c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  EXPECT_EQ(pclose(p), 0);
  EXPECT_NE(out.find("chunks: " + std::to_string(kChunks + 1) + "\n"), std::string::npos) << out.substr(0, 400);
  EXPECT_NE(out.find("named \"floor" + std::to_string(kChunks - 1) + "\""), std::string::npos);
}

}  // namespace
