// Tests of the streaming CARMEN log reader (carmen_compat/log_reader.h) on
// real logs, and its guess of a laser's configuration. Bad input:
// log_reader_bad_input_test.cc; odd data and the line parser:
// log_reader_parse_test.cc.
#include "carmen_compat/log_reader.h"
#include "temp_dir.h"

#include <dirent.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "log_reader_test_support.h"

namespace {

using namespace logtest;

// ---------------------------------------------------------------------------
// Real logs.
//
// Expected counts were produced independently of this reader, by running
//   zcat FILE | awk '{c[$1]++} END {for (k in c) print k, c[k]}'
// over every *.log.gz / *.clf.gz of the shared data set (counting lines by
// their exact first field), and beam counts with
//   zcat FILE | awk '$1=="FLASER"{print $2} $1~/^R(OBOT|AW)LASER/{print $9}' | sort | uniq -c
// which also confirmed that every laser line has exactly the fields its counts
// call for.
struct Expected {
  const char *file;  // relative to the shared data directory
  int flaser, robotlaser1, rawlaser1, odom, param;
  int beams;  // of every laser message
};

const Expected kExpected[] = {
    {"csail-newcarmen.log.gz", 0, 1988, 1988, 4188, 119, 361},
    {"csail-oldcarmen.log.gz", 1988, 1988, 1988, 4188, 119, 361},
    {"csail.corrected.log.gz", 406, 0, 0, 2394, 0, 361},
    {"flirtlib/fr079.log.gz", 0, 1464, 0, 0, 0, 360},
    {"flirtlib/intel-lab.log.gz", 0, 2672, 0, 0, 0, 180},
    {"flirtlib/mit-cscail.log.gz", 0, 1051, 0, 0, 0, 361},
    {"fr079-complete.gfs.log.gz", 4791, 0, 0, 9725, 0, 360},
    {"fr101.carmen.gfs.log.gz", 292, 0, 0, 4569, 0, 360},
    {"fr101.carmen.log.gz", 4758, 0, 0, 8955, 168, 360},
    {"intel.gfs.log.gz", 910, 0, 0, 14541, 0, 180},
    {"ple_radish_corrected/acapulco-corrected.log.gz", 861, 0, 0, 12142, 0, 181},
    {"ple_radish_corrected/aces-corrected.log.gz", 440, 0, 0, 7814, 4, 180},
    {"ple_radish_corrected/belgioioso-corrected.log.gz", 395, 0, 0, 4442, 171, 361},
    {"ple_radish_corrected/csail-corrected.log.gz", 406, 0, 0, 2394, 119, 361},
    {"ple_radish_corrected/edmonton-corrected.log.gz", 340, 0, 0, 6351, 21, 180},
    {"ple_radish_corrected/fhw-corrected.log.gz", 488, 0, 0, 13935, 3, 180},
    {"ple_radish_corrected/freiburg-079-corrected.log.gz", 4791, 0, 0, 9725, 187, 360},
    {"ple_radish_corrected/freiburg-101-corrected.log.gz", 292, 0, 0, 4569, 168, 360},
    {"ple_radish_corrected/freiburg-campus-corrected.log.gz", 2008, 0, 0, 17691, 245, 360},
    {"ple_radish_corrected/infinite-corridor-corrected.log.gz", 1941, 0, 0, 18191, 0, 180},
    {"ple_radish_corrected/intel-corrected.log.gz", 910, 0, 0, 14541, 2, 180},
    {"ple_radish_corrected/orebro-corrected.log.gz", 237, 0, 0, 255, 0, 181},
    {"ple_radish_corrected/seattle-corrected.log.gz", 241, 0, 0, 19311, 0, 361},
    {"slamevaluation/mit-csail.clf.gz", 1988, 0, 0, 0, 0, 361},
};

void find_logs(const std::string &dir, const std::string &rel, std::vector<std::string> &out) {
  DIR *d = opendir(dir.c_str());
  if (!d) return;
  while (dirent *e = readdir(d)) {
    const std::string name = e->d_name;
    if (name == "." || name == "..") continue;
    const std::string full = dir + "/" + name;
    const std::string r = rel.empty() ? name : rel + "/" + name;
    auto ends = [&](const char *s) {
      const size_t n = std::strlen(s);
      return name.size() >= n && name.compare(name.size() - n, n, s) == 0;
    };
    if (is_dir(full)) find_logs(full, r, out);
    else if (ends(".log.gz") || ends(".clf.gz")) out.push_back(r);
  }
  closedir(d);
}

void check_counts(const std::string &path, const Expected &x) {
  SCOPED_TRACE(path);
  LogReader reader(path);  // strict
  LogMessage m;
  long bad_beams = 0;
  while (reader.next(m)) {
    if (carmen::is_laser_message(m.type) && static_cast<int>(m.laser.range.size()) != x.beams)
      ++bad_beams;
  }
  const LogStats &s = reader.stats();
  EXPECT_EQ(s.count(MessageType::FLASER), static_cast<uint64_t>(x.flaser));
  EXPECT_EQ(s.count(MessageType::ROBOTLASER1), static_cast<uint64_t>(x.robotlaser1));
  EXPECT_EQ(s.count(MessageType::RAWLASER1), static_cast<uint64_t>(x.rawlaser1));
  EXPECT_EQ(s.count(MessageType::ODOM), static_cast<uint64_t>(x.odom));
  EXPECT_EQ(s.count(MessageType::PARAM), static_cast<uint64_t>(x.param));
  EXPECT_EQ(s.laser_messages(), static_cast<uint64_t>(x.flaser + x.robotlaser1 + x.rawlaser1));
  EXPECT_EQ(bad_beams, 0);
  EXPECT_EQ(s.total_bad_lines(), 0u);
  EXPECT_EQ(s.nan_ranges + s.inf_ranges + s.negative_ranges, 0u);
  EXPECT_EQ(reader.compressed_bytes_read(), reader.file_size());
}

TEST(LogReaderRealLogs, EverySharedLogParsesStrictlyWithExpectedCounts) {
  const std::string dir = shared_data();
  if (!is_dir(dir))
    GTEST_SKIP() << "the shared data set (" << dir << ") is not present; CI has it";
  std::vector<std::string> logs;
  find_logs(dir, "", logs);
  std::sort(logs.begin(), logs.end());
  ASSERT_GE(logs.size(), 24u);
  for (const std::string &rel : logs) {
    const Expected *x = nullptr;
    for (const Expected &e : kExpected)
      if (rel == e.file) x = &e;
    if (!x) {
      ADD_FAILURE() << rel << ": no expected counts; add it to kExpected (count with zcat | awk)";
      continue;
    }
    check_counts(dir + "/" + rel, *x);
  }
}

TEST(LogReaderRealLogs, BundledLogs) {
  check_counts(bundled_log("fr079-complete.gfs.log.gz"), kExpected[6]);
  check_counts(bundled_log("intel.gfs.log.gz"), kExpected[9]);

  LogStats s;
  const auto msgs = read_all(bundled_log("fr079-complete.gfs.log.gz"), {}, &s);
  EXPECT_EQ(s.unknown_lines, 4791u);  // NEFF
  ASSERT_EQ(s.unknown_names.size(), 1u);
  EXPECT_EQ(s.unknown_names[0].first, "NEFF");
  EXPECT_EQ(s.lines, 19307u);  // zcat | wc -l
  EXPECT_EQ(s.bytes, 9476659u);  // zcat | wc -c
  const LogMessage *first = nullptr;
  for (const auto &m : msgs)
    if (m.type == MessageType::FLASER) {
      first = &m;
      break;
    }
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(first->line, 3);  // zcat | grep -n -m1 FLASER
  EXPECT_EQ(first->laser.config.start_angle, -kPi / 2.0);
  EXPECT_EQ(first->laser.config.angular_resolution, kPi / 360.0);
  EXPECT_EQ(first->laser.config.fov, kPi / 180.0 * 179.5);
  EXPECT_EQ(first->laser.config.maximum_range, 80.0);
  EXPECT_EQ(first->laser.range[0], static_cast<float>(1.65));
  EXPECT_EQ(first->laser.range[1], static_cast<float>(1.66));
  EXPECT_EQ(first->laser.host, "pippo");
  EXPECT_TRUE(first->laser.has_pose);
  EXPECT_EQ(first->laser.id, -1);
}

// An independent parse of every line with strtod (the C locale is in force in
// this test binary), compared field by field, bit for bit, with the reader.
void compare_with_strtod(const std::string &path) {
  SCOPED_TRACE(path);
  const std::string text = gunzip(path);
  ASSERT_FALSE(text.empty());
  LogReader reader(path);
  LogMessage m;
  size_t pos = 0;
  long line_no = 0;
  long compared = 0;
  while (reader.next(m)) {
    std::string line;
    while (line_no < m.line) {  // advance the independent line splitter
      const size_t nl = text.find('\n', pos);
      line = text.substr(pos, nl == std::string::npos ? std::string::npos : nl - pos);
      pos = nl == std::string::npos ? text.size() : nl + 1;
      ++line_no;
    }
    Tokens k = tokenize(line);
    ASSERT_EQ(k.s(), carmen::message_type_name(m.type)) << "line " << m.line;
    auto same = [&](double a, double b) {
      uint64_t x, y;
      std::memcpy(&x, &a, 8);
      std::memcpy(&y, &b, 8);
      return x == y;
    };
    bool ok = true;
    if (carmen::is_laser_message(m.type)) {
      const auto &L = m.laser;
      const bool old = m.type == MessageType::FLASER || m.type == MessageType::RLASER;
      if (!old) {
        ok &= L.config.laser_type == k.l();
        ok &= same(L.config.start_angle, k.d()) && same(L.config.fov, k.d()) &&
              same(L.config.angular_resolution, k.d()) && same(L.config.maximum_range, k.d()) &&
              same(L.config.accuracy, k.d());
        ok &= L.config.remission_mode == k.l();
      }
      const long n = k.l();
      ok &= n == static_cast<long>(L.range.size());
      for (long i = 0; ok && i < n; ++i) {
        const float f = static_cast<float>(k.d());
        ok &= std::memcmp(&f, &L.range[static_cast<size_t>(i)], 4) == 0;
      }
      if (!old) {
        const long r = k.l();
        ok &= r == static_cast<long>(L.remission.size());
        for (long i = 0; ok && i < r; ++i) {
          const float f = static_cast<float>(k.d());
          ok &= std::memcmp(&f, &L.remission[static_cast<size_t>(i)], 4) == 0;
        }
      }
      if (L.has_pose) {
        ok &= same(L.laser_pose.x, k.d()) && same(L.laser_pose.y, k.d()) &&
              same(L.laser_pose.theta, k.d());
        ok &= same(L.robot_pose.x, k.d()) && same(L.robot_pose.y, k.d()) &&
              same(L.robot_pose.theta, k.d());
        if (!old)
          ok &= same(L.tv, k.d()) && same(L.rv, k.d()) && same(L.forward_safety_dist, k.d()) &&
                same(L.side_safety_dist, k.d()) && same(L.turn_axis, k.d());
      }
      ok &= same(L.timestamp, k.d()) && L.host == k.s() && same(L.logger_timestamp, k.d());
      ok &= k.i == k.t.size();
    } else if (m.type == MessageType::ODOM) {
      const auto &o = m.odom;
      ok &= same(o.x, k.d()) && same(o.y, k.d()) && same(o.theta, k.d()) && same(o.tv, k.d()) &&
            same(o.rv, k.d()) && same(o.acceleration, k.d()) && same(o.timestamp, k.d()) &&
            o.host == k.s() && same(o.logger_timestamp, k.d());
      ok &= k.i == k.t.size();
    } else if (m.type == MessageType::PARAM) {
      ok &= m.param.name == k.s() && m.param.value == k.s();
    }
    ASSERT_TRUE(ok) << "line " << m.line << " differs from strtod: " << line.substr(0, 120);
    ++compared;
  }
  EXPECT_GT(compared, 0);
}

TEST(LogReaderRealLogs, FieldsMatchStrtodBitForBit) {
  compare_with_strtod(bundled_log("fr079-complete.gfs.log.gz"));
  compare_with_strtod(bundled_log("intel.gfs.log.gz"));
  const std::string dir = shared_data();
  if (!is_dir(dir)) GTEST_SKIP() << "shared data set absent: only the bundled logs were compared";
  for (const char *f : {"csail-oldcarmen.log.gz", "fr101.carmen.log.gz", "flirtlib/intel-lab.log.gz",
                        "slamevaluation/mit-csail.clf.gz",
                        "ple_radish_corrected/infinite-corridor-corrected.log.gz"})
    compare_with_strtod(dir + "/" + f);
}

TEST(LogReaderRealLogs, PlainAndGzipGiveTheSameMessages) {
  TempDir tmp;
  const std::string gz = bundled_log("intel.gfs.log.gz");
  const std::string plain = tmp.file("intel.gfs.log");
  write_file(plain, gunzip(gz));
  LogReader a(gz), b(plain);
  EXPECT_TRUE(a.compressed());
  EXPECT_FALSE(b.compressed());
  LogMessage ma, mb;
  long n = 0;
  for (;;) {
    const bool ga = a.next(ma), gb = b.next(mb);
    ASSERT_EQ(ga, gb);
    if (!ga) break;
    ASSERT_EQ(ma.type, mb.type);
    ASSERT_EQ(ma.line, mb.line);
    if (ma.type == MessageType::FLASER) {
      ASSERT_EQ(ma.laser.range, mb.laser.range);
      ASSERT_EQ(ma.laser.laser_pose.x, mb.laser.laser_pose.x);
    }
    ++n;
  }
  EXPECT_EQ(n, 910 + 14541);
  EXPECT_EQ(a.stats().bytes, b.stats().bytes);
  EXPECT_EQ(b.compressed_bytes_read(), b.file_size());
  EXPECT_LT(a.file_size(), b.file_size());
}

TEST(LogReaderRealLogs, PaddedFileLikeFr101WithBlankLinesAndHashParam) {
  const std::string path = shared_data() + "/fr101.carmen.log.gz";
  if (!is_dir(shared_data())) GTEST_SKIP() << "shared data set absent";
  LogStats s;
  const auto msgs = read_all(path, {}, &s);
  EXPECT_EQ(s.blank_lines, 1u);
  EXPECT_EQ(s.comment_lines, 12u);  // 11 "# ..." header lines and one "#PARAM"
  ASSERT_FALSE(msgs.empty());
  EXPECT_EQ(msgs[0].type, MessageType::PARAM);
  EXPECT_EQ(msgs[0].param.name, "robot_acceleration");
  EXPECT_EQ(msgs[0].param.value, "0.50");
}

TEST(LogReaderRealLogs, RobotLaserAndRawLaserFields) {
  if (!is_dir(shared_data())) GTEST_SKIP() << "shared data set absent";
  LogReader r(shared_data() + "/csail-newcarmen.log.gz");
  LogMessage m;
  bool robot = false, raw = false;
  while (r.next(m) && !(robot && raw)) {
    if (m.type == MessageType::ROBOTLASER1 && !robot) {
      robot = true;
      EXPECT_EQ(m.laser.id, 1);
      EXPECT_TRUE(m.laser.has_pose);
      EXPECT_EQ(m.laser.range.size(), 361u);
      EXPECT_EQ(m.laser.turn_axis, 1000000.0);
      EXPECT_EQ(m.laser.host, "b21");
    }
    if (m.type == MessageType::RAWLASER1 && !raw) {
      raw = true;
      EXPECT_EQ(m.laser.id, 1);
      EXPECT_FALSE(m.laser.has_pose);
      EXPECT_TRUE(m.laser.remission.empty());
    }
  }
  EXPECT_TRUE(robot && raw);
}

// ---------------------------------------------------------------------------
// Config guessing.

TEST(LogReaderConfig, GuessForEachBeamCount) {
  struct Case {
    int n;
    double fov, step;
  };
  const Case cases[] = {
      {181, kPi, kPi / 180.0},
      {180, kPi / 180.0 * 179.0, kPi / 180.0},
      {361, kPi, kPi / 360.0},
      {360, kPi / 180.0 * 179.5, kPi / 360.0},
      {401, kPi / 180.0 * 100.0, kPi / 720.0},
      {400, kPi / 100.0 * 99.75, kPi / 720.0},
      {100, kPi, kPi / 99.0},
      {541, kPi, kPi / 540.0},
      {2, kPi, kPi / 1.0},
  };
  for (const Case &c : cases) {
    SCOPED_TRACE(c.n);
    EXPECT_EQ(carmen::guess_laser_fov(c.n), c.fov);
    EXPECT_EQ(carmen::guess_laser_angle_increment(c.n), c.step);
    const carmen::LaserConfig g = carmen::guess_laser_config(c.n);
    EXPECT_EQ(g.laser_type, 0);
    EXPECT_EQ(g.start_angle, -kPi / 2.0);
    EXPECT_EQ(g.fov, c.fov);
    EXPECT_EQ(g.angular_resolution, c.step);
    EXPECT_EQ(g.maximum_range, 80.0);
    EXPECT_EQ(g.accuracy, 0.01);
    EXPECT_EQ(g.remission_mode, 0);

    // Through a FLASER line of that many beams.
    std::string line = "FLASER " + std::to_string(c.n);
    for (int i = 0; i < c.n; ++i) line += " 1.5";
    line += " 0 0 0 0 0 0 1.0 h 2.0";
    LogMessage m;
    carmen::LineError err;
    ASSERT_EQ(carmen::parse_log_line(line.data(), line.data() + line.size(), m, &err),
              LineKind::MESSAGE)
        << err.message;
    EXPECT_EQ(m.laser.config.fov, c.fov);
    EXPECT_EQ(m.laser.config.angular_resolution, c.step);
    EXPECT_EQ(m.laser.config.start_angle, -kPi / 2.0);
  }
  // The order of the operations is CARMEN's: divide first. Multiplying first
  // gives a different double for 360 and 400 beams.
  EXPECT_NE(carmen::guess_laser_fov(360), 179.5 * kPi / 180.0);
  EXPECT_NE(carmen::guess_laser_fov(400), 99.75 * kPi / 100.0);
  // CARMEN's degenerate cases, kept: one beam divides by zero.
  EXPECT_TRUE(std::isinf(carmen::guess_laser_angle_increment(1)));
  EXPECT_EQ(carmen::guess_laser_angle_increment(0), -kPi);
}

}  // namespace
