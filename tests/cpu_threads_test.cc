// The multi-threaded CPU backend against the oracle (cpu_double): the same
// grid bytes and the same counts, whatever the number of threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <iostream>
#include <sstream>
#include <thread>

#include "test_seed.h"
#include "test_support.h"
#include "vasco_gpu/internal/cpu_threads_backend.h"

namespace vasco {
namespace {

using testing_support::random_batch;

using testing_support::bundled_log;
using testing_support::load_log;
using testing_support::LoadedLog;

void expect_bit_identical(const std::vector<float> &ref, const std::vector<float> &got,
                          const GridGeometry &geo) {
  testing_support::expect_bit_identical(ref, got, geo, "cpu_threads");
}

void expect_same_counts(const MapStats &ref, const MapStats &got) {
  EXPECT_EQ(ref.scans, got.scans);
  EXPECT_EQ(ref.beams_used, got.beams_used);
  EXPECT_EQ(ref.beams_skipped, got.beams_skipped);
  EXPECT_EQ(ref.cell_updates, got.cell_updates);
}

// Runs cpu_threads with `threads` threads and checks it against `ref`.
void check_threads(const ScanBatch &batch, const MapperParams &params, const GridGeometry &geo,
                   const std::vector<float> &ref, const MapStats &ref_stats, int threads) {
  SCOPED_TRACE(std::to_string(threads) + " threads");
  BackendOptions options;
  options.threads = threads;
  auto renderer = make_renderer("cpu_threads", options);
  EXPECT_EQ(renderer->name(), "cpu_threads");
  MapStats st;
  const std::vector<float> got = render_grid(*renderer, batch, params, geo, &st);
  expect_bit_identical(ref, got, geo);
  expect_same_counts(ref_stats, st);
  EXPECT_GE(st.map_s, st.prep_s);
  const CpuThreadsLoad *load = cpu_threads_load(*renderer);
  ASSERT_NE(load, nullptr);
  EXPECT_EQ(load->threads, threads);
  uint64_t sum = 0;
  for (uint64_t n : load->stripe_updates) sum += n;
  EXPECT_EQ(sum, st.cell_updates);
}

// The oracle's map of a bundled log, computed once per log.
struct Reference {
  LoadedLog log;
  std::vector<float> grid;
  MapStats stats;
};

const Reference &reference(const std::string &name) {
  static std::map<std::string, Reference> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    Reference r;
    r.log = load_log(bundled_log(name), MapperParams{});
    r.grid = render_grid(*make_renderer("cpu_double"), r.log.batch, MapperParams{}, r.log.geo, &r.stats);
    it = cache.emplace(name, std::move(r)).first;
  }
  return it->second;
}

class CpuThreadsLog : public ::testing::TestWithParam<const char *> {};

TEST_P(CpuThreadsLog, BitIdenticalToTheOracle) {
  const Reference &ref = reference(GetParam());
  ASSERT_GT(ref.stats.cell_updates, 0u);
  for (int threads : {1, 2, 3, 16})
    check_threads(ref.log.batch, MapperParams{}, ref.log.geo, ref.grid, ref.stats, threads);
}

INSTANTIATE_TEST_SUITE_P(BundledLogs, CpuThreadsLog,
                         ::testing::Values("fr079-complete.gfs.log.gz", "intel.gfs.log.gz"),
                         [](const ::testing::TestParamInfo<const char *> &info) {
                           return std::string(info.param).substr(0, 5) == "fr079" ? std::string("fr079")
                                                                                  : std::string("intel");
                         });

struct RandomCase {
  double resolution;
  double range_max;
  double range_sure;
  bool shrink_grid;  // a grid smaller than the scans need: beams and starts leave it
};

TEST(CpuThreads, RandomScansWithOddRangesMatchTheOracle) {
  const unsigned seed = testing_support::test_seed();
  SCOPED_TRACE("random seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  const RandomCase cases[] = {
      {0.05, 10.0, 5.0, false}, {0.025, 10.0, 5.0, false}, {0.1, 10.0, 5.0, true},
      {0.037, 4.0, 1.5, false}, {0.5, 10.0, 5.0, false},   {0.2, 3.0, 3.0, true},
      {0.013, 2.0, 0.5, false},
  };
  for (const RandomCase &rc : cases) {
    SCOPED_TRACE("resolution " + std::to_string(rc.resolution) + ", range_max " +
                 std::to_string(rc.range_max) + (rc.shrink_grid ? ", shrunken grid" : ""));
    MapperParams params;
    params.resolution = rc.resolution;
    params.range_max = rc.range_max;
    params.range_sure = rc.range_sure;
    const ScanBatch batch = random_batch(rng, 120, 8);
    GridGeometry geo = size_grid(batch, params);
    if (rc.shrink_grid) {
      geo.size_x = std::max(1, geo.size_x / 2);
      geo.size_y = std::max(1, geo.size_y / 3);
    }
    MapStats rs;
    const auto ref = render_grid(*make_renderer("cpu_double"), batch, params, geo, &rs);
    for (int threads : {1, 2, 3, 16}) check_threads(batch, params, geo, ref, rs, threads);
  }
}

// Scans crowded into a few columns (one thin vertical strip of poses) and a
// single scan: stripes of very uneven work and grids of few columns.
TEST(CpuThreads, UnevenAndTinyInputsMatchTheOracle) {
  const unsigned seed = testing_support::test_seed();
  SCOPED_TRACE("random seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  MapperParams params;
  params.resolution = 0.05;
  {
    ScanBatch batch = random_batch(rng, 60, 0.5);
    const GridGeometry geo = size_grid(batch, params);
    MapStats rs;
    const auto ref = render_grid(*make_renderer("cpu_double"), batch, params, geo, &rs);
    for (int threads : {2, 7, 16}) check_threads(batch, params, geo, ref, rs, threads);
    GridGeometry narrow = geo;
    narrow.size_x = 3;
    const auto ref_narrow = render_grid(*make_renderer("cpu_double"), batch, params, narrow, &rs);
    for (int threads : {2, 16}) check_threads(batch, params, narrow, ref_narrow, rs, threads);
  }
  {
    const ScanBatch batch = random_batch(rng, 1, 0);
    const GridGeometry geo = size_grid(batch, params);
    MapStats rs;
    const auto ref = render_grid(*make_renderer("cpu_double"), batch, params, geo, &rs);
    for (int threads : {1, 4}) check_threads(batch, params, geo, ref, rs, threads);
  }
}

TEST(CpuThreads, AllCoresByDefault) {
  auto renderer = make_renderer("cpu_threads");
  ScanBatch batch;
  const float r[3] = {1.0f, 2.0f, 3.0f};
  batch.add_scan(0, 0, 0, -0.1, 0.1, r, 3, 1);
  MapperParams params;
  const GridGeometry geo = size_grid(batch, params);
  MapStats st;
  render_grid(*renderer, batch, params, geo, &st);
  const CpuThreadsLoad *load = cpu_threads_load(*renderer);
  ASSERT_NE(load, nullptr);
  EXPECT_EQ(load->threads, static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
  EXPECT_EQ(cpu_threads_load(*make_renderer("cpu_double")), nullptr);
}

}  // namespace
}  // namespace vasco
