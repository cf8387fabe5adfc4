// align_maps on real logs: a log split into two sessions that share part of
// the route, the second mapped in a frame moved by a rigid transform the
// test draws; aligning the second session's map to the first's must give
// that transform back within a map cell (0.1 m) and 0.5 degrees. Two
// different buildings must not be aligned.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <random>
#include <string>

#include "test_seed.h"
#include "align_test_support.h"
#include "test_support.h"
#include "vasco_gpu/align.h"
#include "vasco_gpu/internal/se2.h"

namespace {

using vasco::AlignMap;
using vasco::AlignResult;
using vasco::AlignVerdict;
using vasco::Pose2;

constexpr double kPi = 3.14159265358979323846;
constexpr double kCell = 0.1;

vasco::MapperParams params_at_cell() { return vasco::testing_support::params_at_align_cell(); }

AlignMap map_of(const vasco::ScanBatch &scans) { return vasco::testing_support::align_map_of_scans(scans); }

struct Sessions {
  vasco::ScanBatch first, second;
};

// Scans [0, 0.65 n) and [0.35 n, n): 30 % of the route in both.
Sessions split(const std::string &log) {
  const vasco::ScanBatch all = vasco::testing_support::load_log(vasco::testing_support::bundled_log(log), params_at_cell()).batch;
  const long n = static_cast<long>(all.num_scans());
  const long end_first = n * 65 / 100, start_second = n * 35 / 100;
  return {all.select(0, end_first), all.select(start_second, n - start_second)};
}

bool have_log(const std::string &log) { return std::filesystem::exists(vasco::testing_support::bundled_log(log)); }

// The second session recorded in a frame F whose poses are the shared
// frame's taken by T^-1: T takes F into the shared (first session's) frame,
// which is what align_maps must return.
AlignResult align_moved(const Sessions &s, const AlignMap &first_map, const Pose2 &truth) {
  vasco::ScanBatch moved = s.second;
  const Pose2 to_f = vasco::inverse(truth);
  moved.transform(to_f.x, to_f.y, to_f.theta);
  vasco::AlignOptions options;
  options.threads = 2;
  return vasco::align_maps(first_map, map_of(moved), options);
}

class AlignLogs : public ::testing::TestWithParam<const char *> {};

TEST_P(AlignLogs, FindsTheTransformOfASecondSession) {
  const std::string log = GetParam();
  if (!have_log(log)) GTEST_SKIP() << log << " is not in logs/";
  const Sessions s = split(log);
  const AlignMap first_map = map_of(s.first);
  std::mt19937 rng(vasco::testing_support::test_seed());
  std::uniform_real_distribution<double> shift(-20, 20), turn(-kPi, kPi);
  for (int seed = 0; seed < 3; ++seed) {
    const Pose2 truth{shift(rng), shift(rng), turn(rng)};
    const auto t0 = std::chrono::steady_clock::now();
    const AlignResult r = align_moved(s, first_map, truth);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double dtheta = std::abs(std::remainder(r.best.theta - truth.theta, 2 * kPi));
    std::cout << log << " truth (" << truth.x << ", " << truth.y << ", " << truth.theta << "): "
              << vasco::align_verdict_name(r.verdict) << " error (" << r.best.x - truth.x << ", " << r.best.y - truth.y
              << ", " << dtheta * 180 / kPi << " deg) score " << r.best.score << " second " << r.second.score
              << " overlap " << r.overlap << " points " << r.moving_points << " rotations " << r.rotations << " in "
              << seconds << " s (map + align)\n";
    EXPECT_EQ(r.verdict, AlignVerdict::Aligned) << r.reason;
    EXPECT_LE(std::abs(r.best.x - truth.x), kCell);
    EXPECT_LE(std::abs(r.best.y - truth.y), kCell);
    EXPECT_LE(dtheta, 0.5 * kPi / 180);
  }
}

INSTANTIATE_TEST_SUITE_P(Logs, AlignLogs,
                         ::testing::Values("intel.gfs.log.gz", "fr079-complete.gfs.log.gz", "fr101.carmen.log.gz"),
                         [](const auto &info) {  // the building: "intel", "fr079", "fr101"
                           const std::string name = info.param;
                           return name.substr(0, name.find_first_of(".-"));
                         });

// Two buildings: a half of intel against a half of fr079, both ways.
TEST(AlignLogsRefuse, TwoDifferentBuildingsAreNeverAligned) {
  if (!have_log("fr079-complete.gfs.log.gz")) GTEST_SKIP() << "fr079 is not in logs/";
  const AlignMap intel = map_of(split("intel.gfs.log.gz").first);
  const AlignMap fr079 = map_of(split("fr079-complete.gfs.log.gz").second);
  for (const bool swap : {false, true}) {
    const AlignResult r = swap ? vasco::align_maps(fr079, intel, {}) : vasco::align_maps(intel, fr079, {});
    std::cout << (swap ? "fr079 <- intel: " : "intel <- fr079: ") << vasco::align_verdict_name(r.verdict) << " score "
              << r.best.score << " second " << r.second.score << " matched " << r.matched << " (" << r.reason << ")\n";
    EXPECT_NE(r.verdict, AlignVerdict::Aligned);
  }
}

// The benchmark's case on the CPU: two halves of fr079 at 0.1 m on two
// threads (the figure to hold under 3 s), printed with its accuracy.
TEST(AlignLogsTiming, TwoHalvesOfFr079) {
  if (!have_log("fr079-complete.gfs.log.gz")) GTEST_SKIP() << "fr079 is not in logs/";
  const Sessions s = split("fr079-complete.gfs.log.gz");
  const AlignMap first_map = map_of(s.first);
  const Pose2 truth{3.5, -7.25, 2.0};
  vasco::ScanBatch moved = s.second;
  const Pose2 to_f = vasco::inverse(truth);
  moved.transform(to_f.x, to_f.y, to_f.theta);
  const AlignMap second_map = map_of(moved);
  vasco::AlignOptions options;
  options.threads = 2;
  const auto t0 = std::chrono::steady_clock::now();
  const AlignResult r = vasco::align_maps(first_map, second_map, options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "fr079 halves at 0.1 m, 2 threads: " << seconds << " s, error (" << r.best.x - truth.x << ", "
            << r.best.y - truth.y << ", " << std::abs(std::remainder(r.best.theta - truth.theta, 2 * kPi)) * 180 / kPi
            << " deg), maps " << first_map.size_x << " x " << first_map.size_y << " and " << second_map.size_x << " x "
            << second_map.size_y << "\n";
  ::testing::Test::RecordProperty("align_seconds", std::to_string(seconds));
  EXPECT_EQ(r.verdict, AlignVerdict::Aligned) << r.reason;
}

}  // namespace
