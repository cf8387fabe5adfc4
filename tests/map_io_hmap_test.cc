// carmen/map_io.h: the hierarchical-map chunk (HMAP). The expected bytes are
// built by hand from the layout CARMEN writes (zone count, NUL-terminated
// names, link count, then per link type, degree, keys and float x y theta
// points: two per key for a door, one for an elevator).
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "carmen/map_io.h"
#include "carmen_map_free.h"
#include "map_test_support.h"

namespace {

using maptest::free_hmap;

using maptest::chunk;
using maptest::f32;
using maptest::i32;
using maptest::kId;
using maptest::TempDir;

// Three zones; a door between zones 0 and 1, an elevator through all three.
struct Sample {
  char ground[7] = "ground", first[6] = "first", roof[5] = "roof";
  char *names[3] = {ground, first, roof};
  int door_keys[2] = {0, 1}, lift_keys[3] = {0, 1, 2};
  carmen_point_t door_points[4] = {{1, 2, 0.5}, {1.5, 2, 0.5}, {1, 2.5, -0.5}, {1.5, 2.5, -0.5}};
  carmen_point_t lift_points[3] = {{5, 6, 0}, {5, 6, 0.25}, {5, 6, 0.75}};
  carmen_hmap_link_t links[2] = {{CARMEN_HMAP_LINK_DOOR, 2, door_keys, 4, door_points},
                                 {CARMEN_HMAP_LINK_ELEVATOR, 3, lift_keys, 3, lift_points}};
  carmen_hmap_t hmap = {3, names, 2, links};

  static std::string points(const carmen_point_t *p, int n) {
    std::string s;
    for (int i = 0; i < n; ++i) s += f32(float(p[i].x)) + f32(float(p[i].y)) + f32(float(p[i].theta));
    return s;
  }
  std::string payload() const {
    return i32(3) + std::string("ground\0first\0roof\0", 18) + i32(2) + i32(1) + i32(2) + i32(0) + i32(1) +
           points(door_points, 4) + i32(2) + i32(3) + i32(0) + i32(1) + i32(2) + points(lift_points, 3);
  }
};

class MapIoHmap : public ::testing::TestWithParam<const char *> {
 protected:
  std::string path(const std::string &stem) const { return dir_.file(stem + GetParam()); }
  std::string content(const std::string &p) const {
    return std::string(GetParam()).size() > 4 ? maptest::gunzip_file(p) : maptest::read_bytes(p);
  }
  void write(const std::string &p, const std::string &bytes) const {
    if (std::string(GetParam()).size() > 4) {
      maptest::gzip_to_file(p, bytes);
    } else {
      maptest::write_bytes(p, bytes);
    }
  }
  TempDir dir_;
};

TEST_P(MapIoHmap, WritesCarmensBytesAndReadsThemBack) {
  Sample s;
  const std::string file = path("hmap");
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  ASSERT_EQ(carmen_map_write_id(fp), 0);
  ASSERT_EQ(carmen_map_write_hmap_chunk(fp, &s.hmap), 0);
  ASSERT_EQ(carmen_fclose(fp), 0);
  // Size: 10 + 4 + 18 names + 4 + door (8 + 8 + 48) + elevator (8 + 12 + 36).
  EXPECT_EQ(maptest::read_i32(content(file), 18), 10 + 4 + 18 + 4 + 64 + 56);
  EXPECT_EQ(content(file), kId + chunk(3, "HMAP", s.payload()));
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_HMAP_CHUNK), 10 + 4 + 18 + 4 + 64 + 56);

  carmen_hmap_t back;
  ASSERT_EQ(carmen_map_read_hmap_chunk(file.c_str(), &back), 0);
  ASSERT_EQ(back.num_zones, 3);
  EXPECT_STREQ(back.zone_names[0], "ground");
  EXPECT_STREQ(back.zone_names[2], "roof");
  ASSERT_EQ(back.num_links, 2);
  EXPECT_EQ(back.links[0].type, CARMEN_HMAP_LINK_DOOR);
  EXPECT_EQ(back.links[0].num_points, 4);
  EXPECT_EQ(back.links[0].keys[1], 1);
  EXPECT_EQ(back.links[0].points[3].y, 2.5);
  EXPECT_EQ(back.links[0].points[3].theta, -0.5);
  EXPECT_EQ(back.links[1].type, CARMEN_HMAP_LINK_ELEVATOR);
  EXPECT_EQ(back.links[1].degree, 3);
  EXPECT_EQ(back.links[1].num_points, 3);
  EXPECT_EQ(back.links[1].points[2].theta, 0.75);
  free_hmap(back);
}

TEST_P(MapIoHmap, AnEmptyHmapRoundTrips) {
  carmen_hmap_t empty = {0, nullptr, 0, nullptr};
  const std::string file = path("empty");
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_EQ(carmen_map_write_id(fp), 0);
  ASSERT_EQ(carmen_map_write_hmap_chunk(fp, &empty), 0);
  ASSERT_EQ(carmen_fclose(fp), 0);
  EXPECT_EQ(content(file), kId + chunk(3, "HMAP", i32(0) + i32(0)));
  carmen_hmap_t back;
  ASSERT_EQ(carmen_map_read_hmap_chunk(file.c_str(), &back), 0);
  EXPECT_EQ(back.num_zones, 0);
  EXPECT_EQ(back.num_links, 0);
  free_hmap(back);
}

TEST_P(MapIoHmap, BadHmapsAreRefusedOnWriting) {
  Sample s;
  const std::string file = path("bad");
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  testing::internal::CaptureStderr();
  s.links[1].type = 7;
  EXPECT_EQ(carmen_map_write_hmap_chunk(fp, &s.hmap), -1);
  s.links[1].type = CARMEN_HMAP_LINK_ELEVATOR;
  s.lift_keys[2] = 3;  // there are three zones: 0..2
  EXPECT_EQ(carmen_map_write_hmap_chunk(fp, &s.hmap), -1);
  s.lift_keys[2] = 2;
  s.names[1] = nullptr;
  EXPECT_EQ(carmen_map_write_hmap_chunk(fp, &s.hmap), -1);
  EXPECT_EQ(carmen_map_write_hmap_chunk(fp, nullptr), -1);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("unknown type 7"), std::string::npos) << err;
  EXPECT_NE(err.find("key out of range"), std::string::npos) << err;
  ASSERT_EQ(carmen_fclose(fp), 0);
  EXPECT_EQ(content(file), "");
}

TEST_P(MapIoHmap, DamagedChunksAreRefusedOnReading) {
  Sample s;
  const std::string good = s.payload();
  const std::string cases[] = {
      good.substr(0, good.size() - 4),                            // cut short
      good + "x",                                                 // bytes left over
      i32(1) + "no terminator",                                   // zone name without NUL
      i32(-1) + i32(0),                                           // negative zone count
      i32(1) + std::string("a\0", 2) + i32(1) + i32(9) + i32(0),  // unknown link type
      i32(1) + std::string("a\0", 2) + i32(1) + i32(2) + i32(1) + i32(5) + f32(0) + f32(0) + f32(0),  // key 5
      i32(0) + i32(1000000),  // more links than bytes
  };
  carmen_hmap_t back;
  std::memset(&back, 0, sizeof back);
  for (const std::string &payload : cases) {
    const std::string file = path("damaged");
    write(file, kId + chunk(3, "HMAP", payload));
    testing::internal::CaptureStderr();
    EXPECT_EQ(carmen_map_read_hmap_chunk(file.c_str(), &back), -1);
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find(file), std::string::npos) << err;
    EXPECT_EQ(back.zone_names, nullptr);  // cleared: no stale pointer
    EXPECT_EQ(back.num_zones, 0);
  }
  const std::string none = path("none");
  write(none, kId);
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_read_hmap_chunk(none.c_str(), &back), -1);
  EXPECT_EQ(carmen_map_read_hmap_chunk(nullptr, &back), -1);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("has no HMAP chunk"), std::string::npos);
}

// CARMEN's reader finds the first HMAP chunk, named or not, and skips its
// name; a damaged chunk after it does not matter.
TEST_P(MapIoHmap, TheFirstHmapIsReadNamedOrNot) {
  Sample s;
  const std::string file = path("named_hmap");
  const std::string damaged_after = std::string(1, '\x66') + i32(0x7ffffff0) + "JUNK      ";
  write(file, kId + chunk(3, "HMAP", s.payload(), "zones", true) + chunk(3, "HMAP", i32(0) + i32(0)) +
                  damaged_after);
  carmen_hmap_t back;
  std::memset(&back, 0x5a, sizeof back);
  ASSERT_EQ(carmen_map_read_hmap_chunk(file.c_str(), &back), 0);
  ASSERT_EQ(back.num_zones, 3);
  EXPECT_STREQ(back.zone_names[0], "ground");
  EXPECT_STREQ(back.zone_names[2], "roof");
  ASSERT_EQ(back.num_links, 2);
  EXPECT_EQ(back.links[1].type, CARMEN_HMAP_LINK_ELEVATOR);
  EXPECT_EQ(back.links[1].points[2].theta, 0.75);
  free_hmap(back);
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_HMAP_CHUNK), int(10 + 6 + s.payload().size()));
}

// What a forked child saw calling `read`: its result, its stderr, how much
// its peak RSS grew (ru_maxrss) and how long the call took. The child's
// address space is capped at 1 GiB more than it starts with, so that a
// reader that allocates what a file claims fails there, not on the machine.
struct ChildRun {
  int rc = -2;  // -2: the child died
  long rss_growth_mib = -1;
  double seconds = -1;
  std::string err;
};

long vm_bytes() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0;
  statm >> pages;
  return pages * sysconf(_SC_PAGESIZE);
}

template <typename F>
ChildRun run_in_child(F read) {
  int fds[2];
  if (pipe(fds) != 0) return {};
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const long vm = vm_bytes();
    if (vm > 0) {
      const rlimit cap{rlim_t(vm) + (rlim_t(1) << 30), rlim_t(vm) + (rlim_t(1) << 30)};
      setrlimit(RLIMIT_AS, &cap);
    }
    testing::internal::CaptureStderr();
    rusage before{}, after{};
    getrusage(RUSAGE_SELF, &before);
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = read();
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    getrusage(RUSAGE_SELF, &after);
    const std::string err = testing::internal::GetCapturedStderr();
    const std::string out = std::to_string(rc) + " " + std::to_string((after.ru_maxrss - before.ru_maxrss) / 1024) +
                            " " + std::to_string(secs) + "\n" + err;
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
  std::sscanf(got.c_str(), "%d %ld %lf", &r.rc, &r.rss_growth_mib, &r.seconds);
  r.err = got.substr(nl + 1);
  return r;
}

// 16 MiB of NULs claim 16.7 million empty zone names: a 16 KB .map.gz once
// made the reader build 1.2 GB of them. What the C structure would keep is
// counted as the payload is walked, and refused at the HMAP reader's limit
// before anything is allocated for it.
TEST_P(MapIoHmap, MillionsOfEmptyZoneNamesAreRefusedNotAllocated) {
  const std::string file = path("zones");
  const int32_t claimed = 1 << 24;
  write(file, kId + chunk(3, "HMAP", i32(claimed) + std::string(size_t(claimed), '\0') + i32(0)));
  const ChildRun r = run_in_child([&] {
    carmen_hmap_t back;
    const int rc = carmen_map_read_hmap_chunk(file.c_str(), &back);
    if (rc == 0) free_hmap(back);
    return rc;
  });
  EXPECT_EQ(r.rc, -1) << r.err;
  EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("more than 64 MiB"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("refused rather than allocated"), std::string::npos) << r.err;
  EXPECT_GE(r.rss_growth_mib, 0);
  EXPECT_LT(r.rss_growth_mib, 128) << "the payload is 16 MiB; nothing more should have been allocated";
  EXPECT_LT(r.seconds, 5.0);
}

// A chunk claiming more than the limit is refused before its bytes are read
// (a .gz chunk's size is not checked against the file's; a plain file's is).
TEST_P(MapIoHmap, AChunkOverTheLimitIsRefusedBeforeItIsRead) {
  const std::string file = path("big_chunk");
  write(file, kId + std::string(1, '\3') + i32(0x7ffffff0) + "HMAP      " + i32(1000) + std::string(4000, 'a'));
  testing::internal::CaptureStderr();
  carmen_hmap_t back;
  EXPECT_EQ(carmen_map_read_hmap_chunk(file.c_str(), &back), -1);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find(file), std::string::npos) << err;
  if (std::string(GetParam()).size() > 4) {
    EXPECT_NE(err.find("2147483632 bytes, more than the 64 MiB"), std::string::npos) << err;
  } else {
    EXPECT_NE(err.find("truncated or damaged"), std::string::npos) << err;
  }
  EXPECT_EQ(back.zone_names, nullptr);
}

// Many zones within the limit still read, each name its own allocation.
TEST_P(MapIoHmap, ManyZonesWithinTheLimitRead) {
  const int n = 100000;
  std::string names;
  for (int i = 0; i < n; ++i) names += "zone" + std::to_string(i) + '\0';
  const std::string file = path("many");
  write(file, kId + chunk(3, "HMAP", i32(n) + names + i32(1) + i32(CARMEN_HMAP_LINK_ELEVATOR) + i32(2) +
                                         i32(0) + i32(n - 1) + f32(1) + f32(2) + f32(3) + f32(4) + f32(5) +
                                         f32(6)));
  carmen_hmap_t back;
  ASSERT_EQ(carmen_map_read_hmap_chunk(file.c_str(), &back), 0);
  ASSERT_EQ(back.num_zones, n);
  EXPECT_STREQ(back.zone_names[0], "zone0");
  EXPECT_STREQ(back.zone_names[n - 1], ("zone" + std::to_string(n - 1)).c_str());
  ASSERT_EQ(back.num_links, 1);
  EXPECT_EQ(back.links[0].keys[1], n - 1);
  EXPECT_EQ(back.links[0].num_points, 2);
  EXPECT_EQ(back.links[0].points[1].theta, 6);
  free_hmap(back);
}

INSTANTIATE_TEST_SUITE_P(PlainAndGzip, MapIoHmap, ::testing::Values(".map", ".map.gz"), [](const auto &info) {
  return std::string(info.param).size() > 4 ? "gzip" : "plain";
});

}  // namespace
