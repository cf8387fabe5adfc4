// align_maps with its global search on the GPU against the same call on the
// CPU: the verdict the same and the transform the same within the accuracy
// (0.1 m, 0.5 degrees), on a drawn floor plan and on real logs split into
// two sessions, the second moved by transforms the test draws; both also
// within that accuracy of the truth. Skips without a usable GPU.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "test_seed.h"
#include "align_test_support.h"
#include "test_support.h"
#include "vasco_gpu/align.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/internal/se2.h"

namespace {

using vasco::testing_support::distance_to;
using vasco::testing_support::Segment;

using vasco::AlignMap;
using vasco::AlignOptions;
using vasco::AlignResult;
using vasco::AlignVerdict;
using vasco::Pose2;

constexpr double kPi = 3.14159265358979323846;
constexpr double kCell = 0.1;
constexpr double kDegree = kPi / 180;

#define REQUIRE_ALIGN_GPU()                                \
  do {                                                     \
    std::string why_;                                      \
    if (!vasco::gpu_usable(0, &why_)) GTEST_SKIP() << why_; \
  } while (0)

AlignResult align_on(const AlignMap &ref, const AlignMap &mov, AlignOptions::Backend backend) {
  AlignOptions o;
  o.backend = backend;
  o.threads = 2;
  return vasco::align_maps(ref, mov, o);
}

double turn_between(double a, double b) { return std::abs(std::remainder(a - b, 2 * kPi)); }

// The GPU's result is the CPU's: the same candidates from the global search
// (both take the peaks above the floor best first, each unless it is near
// one taken: align_search.h's best_distinct), so the same refined best and
// second, bit for bit, and the same verdict.
void expect_same(const AlignResult &gpu, const AlignResult &cpu) {
  EXPECT_TRUE(gpu.gpu);
  EXPECT_FALSE(cpu.gpu);
  EXPECT_EQ(gpu.verdict, cpu.verdict) << "gpu: " << gpu.reason << " cpu: " << cpu.reason;
  EXPECT_EQ(gpu.rotations, cpu.rotations);
  const auto same = [](const char *which, const vasco::AlignCandidate &g, const vasco::AlignCandidate &c) {
    EXPECT_EQ(g.x, c.x) << which;
    EXPECT_EQ(g.y, c.y) << which;
    EXPECT_EQ(g.theta, c.theta) << which;
    EXPECT_EQ(g.score, c.score) << which;
  };
  same("best", gpu.best, cpu.best);
  EXPECT_EQ(gpu.has_second, cpu.has_second);
  if (gpu.has_second && cpu.has_second) same("second", gpu.second, cpu.second);
}

void expect_truth(const AlignResult &r, const Pose2 &truth) {
  EXPECT_EQ(r.verdict, AlignVerdict::Aligned) << r.reason << " (best " << r.best.x << ", " << r.best.y << ", "
                                              << r.best.theta << ")";
  EXPECT_LE(std::abs(r.best.x - truth.x), kCell);
  EXPECT_LE(std::abs(r.best.y - truth.y), kCell);
  EXPECT_LE(turn_between(r.best.theta, truth.theta), 0.5 * kDegree);
}

// ---- a drawn floor plan -------------------------------------------------

// A 24 x 14 m floor with rooms of different sizes and doors: no symmetry.
const std::vector<Segment> &plan_walls() {
  static const std::vector<Segment> walls = {
      {0, 0, 24, 0},   {24, 0, 24, 14},  {24, 14, 0, 14},  {0, 14, 0, 0},    {7, 0, 7, 5},     {7, 6.5, 7, 14},
      {7, 9, 11, 9},   {12.5, 9, 17, 9}, {17, 9, 17, 14},  {15, 0, 15, 3.5}, {15, 5, 15, 6},   {15, 6, 20, 6},
      {21.5, 6, 24, 6}, {2, 3, 4.5, 3},  {19, 11, 19, 12.5}, {10, 3, 12, 4.5}};
  return walls;
}

// The plan mapped in frame `frame` (T takes it into the plan's), at 0.05 m
// cells, over the part of the plan in world x within [wx0, wx1]: walls 0.1 m
// thick, free inside, unknown outside.
AlignMap plan_map(const Pose2 &frame, double wx0, double wx1) {
  const double r = 0.05;
  const Pose2 to_frame = vasco::inverse(frame);
  double lo_x = 1e9, lo_y = 1e9, hi_x = -1e9, hi_y = -1e9;
  for (const double cx : {wx0, wx1})
    for (const double cy : {0.0, 14.0}) {
      const Pose2 q = vasco::compose(to_frame, Pose2{cx, cy, 0});
      lo_x = std::min(lo_x, q.x), hi_x = std::max(hi_x, q.x), lo_y = std::min(lo_y, q.y), hi_y = std::max(hi_y, q.y);
    }
  AlignMap m;
  m.resolution = r;
  m.origin_x = lo_x - 1;
  m.origin_y = lo_y - 1;
  m.size_x = static_cast<int>((hi_x - lo_x + 2) / r);
  m.size_y = static_cast<int>((hi_y - lo_y + 2) / r);
  m.cells.assign(static_cast<size_t>(m.size_x) * m.size_y, -1.0f);
  for (int x = 0; x < m.size_x; ++x)
    for (int y = 0; y < m.size_y; ++y) {
      const Pose2 w = vasco::compose(frame, Pose2{m.origin_x + (x + 0.5) * r, m.origin_y + (y + 0.5) * r, 0});
      if (w.x < wx0 || w.x > wx1 || w.y < -0.2 || w.y > 14.2) continue;
      float v = w.x > 0 && w.x < 24 && w.y > 0 && w.y < 14 ? 0.05f : -1.0f;
      for (const Segment &s : plan_walls())
        if (distance_to(s, w.x, w.y) <= 0.05) v = 0.9f;
      m.cells[static_cast<size_t>(x) * m.size_y + y] = v;
    }
  return m;
}

// The plan test's truths (the same seed), drawn alike.
std::vector<Pose2> plan_truths() {
  std::mt19937 rng(vasco::testing_support::test_seed());
  std::uniform_real_distribution<double> shift(-15, 15), turn(-kPi, kPi);
  std::vector<Pose2> truths;
  for (int seed = 0; seed < 3; ++seed) {
    const double x = shift(rng), y = shift(rng);
    truths.push_back({x, y, turn(rng)});
  }
  return truths;
}

TEST(AlignCuda, GpuFindsTheCpusTransformOnAPlan) {
  REQUIRE_ALIGN_GPU();
  const AlignMap reference = plan_map({0, 0, 0}, -1, 19);
  for (const Pose2 &truth : plan_truths()) {
    const AlignMap moving = plan_map(truth, 5, 25);
    const AlignResult gpu = align_on(reference, moving, AlignOptions::Backend::Gpu);
    const AlignResult cpu = align_on(reference, moving, AlignOptions::Backend::Cpu);
    std::cout << "plan truth (" << truth.x << ", " << truth.y << ", " << truth.theta << "): gpu ("
              << gpu.best.x << ", " << gpu.best.y << ", " << gpu.best.theta << ") score " << gpu.best.score
              << ", cpu (" << cpu.best.x << ", " << cpu.best.y << ", " << cpu.best.theta << ") score "
              << cpu.best.score << "\n";
    expect_same(gpu, cpu);
    expect_truth(gpu, truth);
  }
}

// A moving map without a wall: both backends refuse it.
TEST(AlignCuda, GpuRefusesAsTheCpuDoes) {
  REQUIRE_ALIGN_GPU();
  AlignMap empty_moving = plan_map({3, 2, 1}, 5, 25);
  std::fill(empty_moving.cells.begin(), empty_moving.cells.end(), 0.05f);  // no wall at all
  const AlignMap reference = plan_map({0, 0, 0}, -1, 19);
  const AlignResult gpu = align_on(reference, empty_moving, AlignOptions::Backend::Gpu);
  EXPECT_EQ(gpu.verdict, AlignVerdict::NoOverlap);
  EXPECT_EQ(gpu.verdict, align_on(reference, empty_moving, AlignOptions::Backend::Cpu).verdict);
}

vasco::MapperParams params_at_cell() { return vasco::testing_support::params_at_align_cell(); }

AlignMap map_of(const vasco::ScanBatch &scans) { return vasco::testing_support::align_map_of_scans(scans); }

class AlignCudaLogs : public ::testing::TestWithParam<const char *> {};

// Scans [0, 0.65 n) as the reference, [0.35 n, n) moved by a drawn T.
TEST_P(AlignCudaLogs, GpuFindsTheCpusTransformOfASecondSession) {
  REQUIRE_ALIGN_GPU();
  const std::string log = vasco::testing_support::bundled_log(GetParam());
  if (!std::filesystem::exists(log)) GTEST_SKIP() << GetParam() << " is not in logs/";
  const vasco::ScanBatch all = vasco::testing_support::load_log(log, params_at_cell()).batch;
  const long n = static_cast<long>(all.num_scans());
  const AlignMap first = map_of(all.select(0, n * 65 / 100));
  const vasco::ScanBatch second = all.select(n * 35 / 100, n - n * 35 / 100);
  std::mt19937 rng(vasco::testing_support::test_seed());
  std::uniform_real_distribution<double> shift(-20, 20), turn(-kPi, kPi);
  for (int seed = 0; seed < 2; ++seed) {
    const Pose2 truth{shift(rng), shift(rng), turn(rng)};
    vasco::ScanBatch moved = second;
    const Pose2 to_f = vasco::inverse(truth);
    moved.transform(to_f.x, to_f.y, to_f.theta);
    const AlignMap moving = map_of(moved);
    const AlignResult gpu = align_on(first, moving, AlignOptions::Backend::Gpu);
    const AlignResult cpu = align_on(first, moving, AlignOptions::Backend::Cpu);
    std::cout << GetParam() << " truth (" << truth.x << ", " << truth.y << ", " << truth.theta << "): gpu error ("
              << gpu.best.x - truth.x << ", " << gpu.best.y - truth.y << ", "
              << turn_between(gpu.best.theta, truth.theta) / kDegree << " deg), cpu error (" << cpu.best.x - truth.x
              << ", " << cpu.best.y - truth.y << ", " << turn_between(cpu.best.theta, truth.theta) / kDegree
              << " deg), second " << gpu.second.score << " / " << cpu.second.score << "\n";
    expect_same(gpu, cpu);
    expect_truth(gpu, truth);
  }
}

INSTANTIATE_TEST_SUITE_P(Logs, AlignCudaLogs, ::testing::Values("intel.gfs.log.gz", "fr079-complete.gfs.log.gz"),
                         [](const auto &info) {
                           const std::string name = info.param;
                           return name.substr(0, name.find_first_of(".-"));
                         });

// Backend Gpu without a usable GPU is an error, never a silent CPU run;
// Auto then runs on the CPU, and finds the plan test's truths there. (Runs
// where no GPU is: the other tests skip.)
TEST(AlignCudaBackend, GpuWithoutAGpuThrowsNoGpuAndAutoRunsOnTheCpu) {
  std::string why;
  if (vasco::gpu_usable(0, &why)) GTEST_SKIP() << "a GPU is usable here";
  const AlignMap reference = plan_map({0, 0, 0}, -1, 19);
  for (const Pose2 &truth : plan_truths()) {
    const AlignMap moving = plan_map(truth, 5, 25);
    try {
      align_on(reference, moving, AlignOptions::Backend::Gpu);
      ADD_FAILURE() << "backend Gpu ran without a GPU";
    } catch (const vasco::Error &e) {
      EXPECT_EQ(e.code(), vasco::ErrorCode::NoGpu) << e.what();
    }
    const AlignResult r = align_on(reference, moving, AlignOptions::Backend::Auto);
    EXPECT_FALSE(r.gpu);
    expect_truth(r, truth);
  }
}

}  // namespace
