// One render split across GPUs (BackendOptions::split_devices) equals one
// device's render bit for bit, in both CUDA modes: the full-resolution grid,
// the finished map and the update count, for a bundled log, for random scans
// with odd ranges (degenerate lines included) across many bands, and for a
// Mapper session fed in pieces; finished on the bands' GPUs (downsample 4,
// 1) and on the host (3). With one GPU the bands share it (devices
// {0, 0, ...}): every line of the split runs, but not on several devices at
// once. The bands' layout is checked without a GPU. Skips without a GPU.
#include <gtest/gtest.h>

#include <random>

#include "golden_support.h"
#include "test_seed.h"
#include "test_support.h"
#include "vasco_gpu/mapper.hpp"

#if defined(VASCO_HAVE_CUDA)
#include "cuda/split_renderer.h"
#endif

namespace vasco {
namespace {

using testing_support::bundled_log;

// `parts` bands over the GPUs there are: device i % count, so one GPU holds
// them all.
std::vector<int> split_over_gpus(int parts) {
  const int count = std::max(cuda_device_count(), 1);
  std::vector<int> devices;
  for (int i = 0; i < parts; ++i) devices.push_back(i % count);
  return devices;
}

BackendOptions cuda_options(CudaMode mode, int parts) {
  BackendOptions o;
  o.cuda_mode = mode;
  if (parts > 1) o.split_devices = split_over_gpus(parts);
  return o;
}

const char *mode_name(CudaMode mode) { return mode == CudaMode::Exact ? "exact" : "float"; }

struct Render {
  std::vector<float> grid;
  std::string finished, finished_by_3;  // downsample 4 (each band's blocks on its GPU), 3 (gathered on the host)
  uint64_t updates = 0;
};

Render render_on(const BackendOptions &o, const ScanBatch &batch, const MapperParams &params, const GridGeometry &geo) {
  auto r = make_renderer("cuda", o);
  Render out;
  MapStats st;
  out.grid = render_grid(*r, batch, params, geo, &st);
  out.updates = st.cell_updates;
  out.finished = golden::digest(r->finish(4, 20));
  out.finished_by_3 = golden::digest(r->finish(3, 7));
  return out;
}

void expect_split_equals_one(const ScanBatch &batch, const MapperParams &params, const GridGeometry &geo,
                             const std::vector<int> &parts_list) {
  for (CudaMode mode : {CudaMode::Float, CudaMode::Exact}) {
    const Render one = render_on(cuda_options(mode, 1), batch, params, geo);
    ASSERT_GT(one.updates, 0u);
    for (int parts : parts_list) {
      SCOPED_TRACE(std::string(mode_name(mode)) + " mode, " + std::to_string(parts) + " bands over a grid " +
                   std::to_string(geo.size_x) + " cells wide");
      const Render split = render_on(cuda_options(mode, parts), batch, params, geo);
      testing_support::expect_bit_identical(one.grid, split.grid, geo, "split");
      EXPECT_EQ(one.finished, split.finished);
      EXPECT_EQ(one.finished_by_3, split.finished_by_3);
      EXPECT_EQ(one.updates, split.updates);
    }
  }
}

#if defined(VASCO_HAVE_CUDA)
TEST(SplitColumns, BandsAreWholeTileColumnsThatCoverTheFrame) {
  for (int size : {1, 31, 32, 33, 100, 1000, 4097, 65536}) {
    for (int parts : {2, 3, 4, 8}) {
      SCOPED_TRACE(std::to_string(size) + " columns in " + std::to_string(parts) + " parts");
      const std::vector<ColumnBand> bands = split_columns(size, parts);
      EXPECT_EQ(bands.size(), static_cast<size_t>(std::min(parts, (size + kBandAlign - 1) / kBandAlign)));
      int next = 0;
      for (const ColumnBand &b : bands) {
        EXPECT_EQ(b.x0, next);
        EXPECT_EQ(b.x0 % kBandAlign, 0);
        EXPECT_GT(b.width, 0);
        next = b.x0 + b.width;
      }
      EXPECT_EQ(next, size);
      // As equal as whole tile columns allow: widths differ by one unit at most.
      int lo = INT_MAX, hi = 0;
      for (size_t i = 0; i + 1 < bands.size(); ++i) {
        lo = std::min(lo, bands[i].width);
        hi = std::max(hi, bands[i].width);
      }
      if (bands.size() > 1) {
        EXPECT_LE(hi - lo, kBandAlign);
      }
    }
  }
  const std::vector<ColumnBand> wide = split_columns(kMaxBandedSide + 1, 2);
  ASSERT_EQ(wide.size(), 1u);
  EXPECT_EQ(wide[0].width, kMaxBandedSide + 1);
}
#endif

TEST(SplitRender, ABundledLogInBandsEqualsOneDevice) {
  REQUIRE_GPU();
  MapperParams params;
  const auto log = testing_support::load_log(bundled_log("intel.gfs.log.gz"), params);
  expect_split_equals_one(log.batch, params, log.geo, {2, 3, 8});
}

// Random poses and odd ranges (NaN, +-inf, negative, >= 50): -inf ends a
// beam near INT_MIN, a line walked step by step, which a band must walk as
// the whole grid does; beams start in one band and end in another.
TEST(SplitRender, OddRangesAcrossManyBandsEqualOneDevice) {
  REQUIRE_GPU();
  const unsigned seed = testing_support::test_seed();
  SCOPED_TRACE("random seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  MapperParams params;
  params.resolution = 0.05;
  const ScanBatch batch = testing_support::random_batch(rng, 120, 9);
  const GridGeometry geo = size_grid(batch, params);
  ASSERT_GT(geo.size_x, 5 * 32);  // every band of five holds columns
  expect_split_equals_one(batch, params, geo, {2, 5});
}

// A frame narrower than one band per device: fewer bands, the same map.
TEST(SplitRender, AFrameNarrowerThanTheBandsEqualsOneDevice) {
  REQUIRE_GPU();
  MapperParams params;
  params.resolution = 0.5;
  std::mt19937 rng(7);
  const ScanBatch batch = testing_support::random_batch(rng, 30, 2);
  const GridGeometry geo = size_grid(batch, params);
  expect_split_equals_one(batch, params, geo, {2, 4});
}

// A session over a split: fed in pieces (grown frames, inserts applied to
// the bands), rendered again after new poses, read through windows that
// cross band borders.
TEST(SplitRender, AMapperSessionOverBandsEqualsOneDevice) {
  REQUIRE_GPU();
  MapperParams params;
  const auto log = testing_support::load_log(bundled_log("intel.gfs.log.gz"), params);
  for (CudaMode mode : {CudaMode::Float, CudaMode::Exact}) {
    SCOPED_TRACE(mode_name(mode));
    Mapper one(params, "cuda", cuda_options(mode, 1)), split(params, "cuda", cuda_options(mode, 3));
    for (size_t a = 0; a < log.batch.num_scans(); a += 211) {
      const ScanBatch piece = log.batch.select(static_cast<long>(a), 211);
      one.insert(piece);
      split.insert(piece);
    }
    EXPECT_EQ(golden::digest(one.finish(4, 20)), golden::digest(split.finish(4, 20)));
    std::vector<Pose> poses = one.poses();
    for (Pose &p : poses) p.theta += 0.01;
    one.render(poses);
    split.render(poses);
    EXPECT_EQ(golden::digest(one.finish(1, 0)), golden::digest(split.finish(1, 0)));
    const GridGeometry f = one.frame();
    const GridWindow w{f.size_x / 3 - 17, f.size_y / 4, f.size_x / 3 + 40, f.size_y / 2};
    testing_support::expect_bit_identical(one.read(w), split.read(w), GridGeometry{w.width, w.height}, "split");
    testing_support::expect_bit_identical(one.read(), split.read(), f, "split");
  }
}

}  // namespace
}  // namespace vasco
