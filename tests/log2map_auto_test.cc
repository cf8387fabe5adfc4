// log2map --add INPUT@auto: intel split into two sessions that share part of
// the route, the second written in a frame moved by a transform T the test
// chooses. log2map must find T (within a map cell and 0.5 degrees), print
// it, map exactly as --add INPUT@T with the printed T, and refuse (exit 1,
// nothing written, the session's file named) a session from another
// building or one a hint keeps away from the truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "log2map_test_support.h"

namespace {

using log2maptest::contains;
using log2maptest::log2map;
using log2maptest::TempDir;
using log2maptest::ToolRun;

constexpr double kPi = 3.14159265358979323846;
const std::string kFr079 = std::string(VASCO_LOGS_DIR) + "/fr079-complete.gfs.log.gz";

struct Pose {
  double x, y, theta;
};

std::string g17(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

std::vector<std::string> flaser_lines(const std::string &gz) {
  std::istringstream in(maptest::gunzip_file(gz));
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);)
    if (line.rfind("FLASER ", 0) == 0) out.push_back(line);
  return out;
}

// A FLASER line with its laser and robot poses taken by t (written out
// here: x' = tx + cos(a) x - sin(a) y, y' = ty + sin(a) x + cos(a) y).
std::string moved(const std::string &line, const Pose &t) {
  std::vector<std::string> tok;
  std::istringstream ls(line);
  for (std::string s; ls >> s;) tok.push_back(s);
  const size_t at = 2 + std::stoul(tok[1]);
  for (size_t p : {at, at + 3}) {
    const double x = std::stod(tok[p]), y = std::stod(tok[p + 1]), th = std::stod(tok[p + 2]);
    tok[p] = g17(t.x + std::cos(t.theta) * x - std::sin(t.theta) * y);
    tok[p + 1] = g17(t.y + std::sin(t.theta) * x + std::cos(t.theta) * y);
    tok[p + 2] = g17(th + t.theta);
  }
  std::string s;
  for (size_t i = 0; i < tok.size(); ++i) s += (i ? " " : "") + tok[i];
  return s;
}

// The inverse of T: the frame the second session was recorded in.
Pose inverse(const Pose &t) {
  const double c = std::cos(t.theta), s = std::sin(t.theta);
  return {-(c * t.x + s * t.y), -(-s * t.x + c * t.y), -t.theta};
}

// Scans [begin, end) of `lines` as a log, each moved by `frame`.
std::string log_of(const std::vector<std::string> &lines, size_t begin, size_t end, const Pose &frame) {
  std::string s;
  for (size_t i = begin; i < end; ++i) s += moved(lines[i], frame) + "\n";
  return s;
}

// The numbers of a JSON array "key":[a,b,c] (the first after `from`).
std::vector<double> json_numbers(const std::string &json, const std::string &key, size_t from = 0) {
  const size_t at = json.find("\"" + key + "\":[", from);
  if (at == std::string::npos) return {};
  std::vector<double> v;
  std::istringstream in(json.substr(at + key.size() + 4, json.find(']', at) - at - key.size() - 4));
  for (std::string n; std::getline(in, n, ',');) v.push_back(std::stod(n));
  return v;
}

double angle_error_deg(double a, double b) { return std::abs(std::remainder(a - b, 2 * kPi)) * 180 / kPi; }

class Log2MapAuto : public ::testing::Test {
 protected:
  // intel's scans [0, 0.65 n) as the first session, [0.35 n, n) recorded
  // in a frame moved by truth^-1 as the second: 30 % of the route shared.
  void SetUp() override {
    const std::vector<std::string> lines = flaser_lines(log2maptest::kIntel);
    const size_t n = lines.size();
    maptest::write_bytes(dir_.file("first.log"), log_of(lines, 0, n * 65 / 100, {0, 0, 0}));
    maptest::write_bytes(dir_.file("second.log"), log_of(lines, n * 35 / 100, n, inverse(kTruth)));
  }
  const Pose kTruth{3.5, -7.25, 2.0};
  TempDir dir_;
};

TEST_F(Log2MapAuto, FindsTheTransformAndMapsAsIfItWereGiven) {
  TempDir found_dir, given_dir;
  const ToolRun r = log2map({"--backend", "cpu_double", "--json", dir_.file("first.log"), "--add",
                             dir_.file("second.log") + "@auto", found_dir.file("m.pgm")});
  ASSERT_EQ(r.status, 0) << r.output;
  const std::vector<double> t = json_numbers(r.output, "transform", r.output.find("\"added_sessions\""));
  ASSERT_EQ(t.size(), 3u) << r.output;
  EXPECT_LE(std::abs(t[0] - kTruth.x), 0.1) << r.output;
  EXPECT_LE(std::abs(t[1] - kTruth.y), 0.1) << r.output;
  EXPECT_LE(angle_error_deg(t[2], kTruth.theta), 0.5) << r.output;
  EXPECT_TRUE(contains(r.output, "\"aligned\":\"auto\"")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"sessions\":2")) << r.output;
  for (const char *key : {"\"score\":", "\"second_score\":", "\"overlap\":", "\"second_transform\":"})
    EXPECT_TRUE(contains(r.output, key)) << key << "\n" << r.output;
  EXPECT_TRUE(contains(r.output, "second.log: aligned (@auto): transform " + g17(t[0]) + "," + g17(t[1]) + "," +
                                     g17(t[2])))
      << r.output;
  // The printed transform, given back, maps the same bytes.
  const ToolRun g = log2map({"--backend", "cpu_double", "-q", dir_.file("first.log"), "--add",
                             dir_.file("second.log") + "@" + g17(t[0]) + "," + g17(t[1]) + "," + g17(t[2]),
                             given_dir.file("m.pgm")});
  ASSERT_EQ(g.status, 0) << g.output;
  EXPECT_EQ(maptest::read_bytes(found_dir.file("m.pgm")), maptest::read_bytes(given_dir.file("m.pgm")));
  EXPECT_EQ(maptest::read_bytes(found_dir.file("m.yaml")), maptest::read_bytes(given_dir.file("m.yaml")));
}

TEST_F(Log2MapAuto, AGivenSessionIsReportedAsGiven) {
  const ToolRun r = log2map({"--backend", "cpu_double", "-q", "--json", dir_.file("first.log"), "--add",
                             dir_.file("second.log") + "@3.5,-7.25,2", dir_.file("m.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "\"aligned\":\"given\",\"score\":null")) << r.output;
  EXPECT_EQ(json_numbers(r.output, "transform", r.output.find("\"added_sessions\"")),
            (std::vector<double>{3.5, -7.25, 2.0}));
}

TEST_F(Log2MapAuto, AnotherBuildingIsRefusedAndNothingWritten) {
  if (!maptest::file_exists(kFr079)) GTEST_SKIP() << "fr079 is not in logs/";
  const std::vector<std::string> fr079 = flaser_lines(kFr079);
  maptest::write_bytes(dir_.file("fr079.log"), log_of(fr079, fr079.size() / 2, fr079.size(), {0, 0, 0}));
  TempDir out;
  const ToolRun r = log2map({"--json", dir_.file("first.log"), "--add", dir_.file("fr079.log") + "@auto",
                             out.file("m.map"), out.file("m.pgm")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(out.entries().empty()) << out.entries().front();
  EXPECT_TRUE(contains(r.output, dir_.file("fr079.log") + ": not placed by alignment")) << r.output;
  EXPECT_TRUE(contains(r.output, "best (")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"error\":{\"file\":")) << r.output;
}

// A hint 10 m from the truth, searched within 1 m: the truth is out of
// reach, so the session is refused, or placed worse than without the hint
// and away from the truth.
TEST_F(Log2MapAuto, AHintThatExcludesTheTruthFindsNoBetter) {
  TempDir out;
  const ToolRun free_search = log2map({"--json", "-q", dir_.file("first.log"), "--add", dir_.file("second.log") + "@auto",
                                       out.file("free.map")});
  ASSERT_EQ(free_search.status, 0) << free_search.output;
  const ToolRun r = log2map({"--json", "-q", dir_.file("first.log"), "--add",
                             dir_.file("second.log") + "@auto:13.5,-7.25,2\u00b11,0.05", out.file("hinted.map")});
  if (r.status == 1) {
    EXPECT_TRUE(contains(r.output, "second.log: not placed by alignment")) << r.output;
    EXPECT_FALSE(maptest::file_exists(out.file("hinted.map")));
    return;
  }
  ASSERT_EQ(r.status, 0) << r.output;
  const auto score = [](const std::string &json) {
    const size_t at = json.find("\"score\":");
    return std::stod(json.substr(at + 8));
  };
  EXPECT_LT(score(r.output), score(free_search.output)) << r.output;
  const std::vector<double> t = json_numbers(r.output, "transform", r.output.find("\"added_sessions\""));
  ASSERT_EQ(t.size(), 3u);
  EXPECT_GT(std::hypot(t[0] - kTruth.x, t[1] - kTruth.y), 5.0) << r.output;
}

TEST(Log2MapAutoUsage, BadHintsAreUsageErrors) {
  TempDir dir;
  for (const std::string hint : {"auto:1,2", "auto:1,2,3+-", "auto:1,2,3+-x", "auto:1,2,3+--1", "auto:1,2,3+-1,nan",
                                 "auto:"}) {
    const ToolRun r = log2map({log2maptest::kIntel, "--add", log2maptest::kIntel + "@" + hint, dir.file("m.map")});
    EXPECT_EQ(r.status, 2) << hint << "\n" << r.output;
    EXPECT_FALSE(maptest::file_exists(dir.file("m.map"))) << hint;
  }
}

}  // namespace
