// cpu_float updates exactly the cells cpu_double updates (cpu_float_backend.cc:
// the oracle's beams, walks and stops), on random scans with odd ranges (NaN,
// +-inf, negative, past 50 m) and parameter sets from a one-cell table to one
// too large to tabulate: its sums cover a box bounded by the ranges before
// any beam is placed, and a bound too tight would leave cells unknown here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "test_seed.h"
#include "test_support.h"
#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/renderer.h"

namespace vasco {
namespace {

struct ParamCase {
  const char *what;
  double resolution, range_max;
  double shrink;  // the grid's share of its size_grid size
};

TEST(CpuFloat, RandomScansUpdateTheCellsCpuDoubleUpdates) {
  const unsigned seed = testing_support::test_seed();
  SCOPED_TRACE("random seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  const ParamCase cases[] = {
      {"defaults", 0.025, 10.0, 1.0},
      {"coarse", 0.05, 10.0, 1.0},
      {"shrunken grid (starts outside it)", 0.1, 10.0, 0.3},
      {"short table (walks cut before their end)", 0.05, 1.0, 1.0},
      {"one-cell table", 0.5, 0.6, 1.0},
      {"too large to tabulate (every beam walked)", 0.002, 3.0, 1.0},
  };
  for (const ParamCase &pc : cases) {
    SCOPED_TRACE(pc.what);
    MapperParams params;
    params.resolution = pc.resolution;
    params.range_max = pc.range_max;
    params.range_sure = std::min(params.range_sure, pc.range_max / 2);
    const ScanBatch batch = testing_support::random_batch(rng, 40, pc.resolution < 0.01 ? 0.5 : 4);
    GridGeometry geo = size_grid(batch, params);
    geo.size_x = std::max(1, static_cast<int>(geo.size_x * pc.shrink));
    geo.size_y = std::max(1, static_cast<int>(geo.size_y * pc.shrink * 0.8));
    MapStats want_stats, got_stats;
    const std::vector<float> want = render_grid(*make_renderer("cpu_double"), batch, params, geo, &want_stats);
    const std::vector<float> got = render_grid(*make_renderer("cpu_float"), batch, params, geo, &got_stats);
    ASSERT_EQ(want.size(), got.size());
    size_t known = 0, differ = 0;
    for (size_t i = 0; i < want.size(); ++i) {
      const bool k = want[i] != egrid::kUnknown;
      known += k;
      if (k != (got[i] != egrid::kUnknown) && ++differ <= 5)
        ADD_FAILURE() << "cell " << i << ": cpu_double " << want[i] << ", cpu_float " << got[i];
    }
    EXPECT_EQ(differ, 0u);
    EXPECT_GT(known, 20u) << "the case must update cells to mean anything";
    EXPECT_EQ(got_stats.cell_updates, want_stats.cell_updates);
    EXPECT_EQ(got_stats.beams_used, want_stats.beams_used);
    EXPECT_EQ(got_stats.beams_skipped, want_stats.beams_skipped);
  }
}

// Short beams (finite ranges, negative ones among them: such a beam points
// backwards, |range + wall| long) from starts close together, in a grid sized
// for range_max: the sums' box is far smaller than the grid here, so a reach
// bound short by a cell leaves cells unknown that cpu_double updates.
TEST(CpuFloat, ShortBeamsInALargeGridUpdateTheCellsCpuDoubleUpdates) {
  const unsigned seed = testing_support::test_seed();
  SCOPED_TRACE("random seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(-0.3, 0.3), ang(-M_PI, M_PI), r(-2.0, 2.5);
  for (double resolution : {0.05, 0.037, 0.1}) {
    SCOPED_TRACE("resolution " + std::to_string(resolution));
    MapperParams params;
    params.resolution = resolution;
    params.range_max = 20.0;
    ScanBatch batch;
    for (int s = 0; s < 30; ++s) {
      std::vector<float> ranges(181);
      for (float &v : ranges) v = static_cast<float>(r(rng));
      batch.add_scan(pos(rng), pos(rng), ang(rng), -M_PI / 2, M_PI / 180, ranges.data(), 181, s + 1);
    }
    const GridGeometry geo = size_grid(batch, params);
    MapStats want_stats, got_stats;
    const std::vector<float> want = render_grid(*make_renderer("cpu_double"), batch, params, geo, &want_stats);
    const std::vector<float> got = render_grid(*make_renderer("cpu_float"), batch, params, geo, &got_stats);
    size_t known = 0, differ = 0;
    for (size_t i = 0; i < want.size(); ++i) {
      known += want[i] != egrid::kUnknown;
      differ += (want[i] != egrid::kUnknown) != (got[i] != egrid::kUnknown);
    }
    EXPECT_EQ(differ, 0u) << "of " << known << " cells known to cpu_double";
    EXPECT_LT(known * 4, want.size()) << "the beams must reach a small part of the grid to test the box";
    EXPECT_EQ(got_stats.cell_updates, want_stats.cell_updates);
  }
}

// Angles that overflow: each of a scan's pose angle, first angle and step is
// finite, but the running sum of the steps reaches inf, so those beams' end
// cells are no cells and their lines are walked to the table's cut, however
// short the ranges (the box is then the cut around the start).
TEST(CpuFloat, AnglesThatOverflowUpdateTheCellsCpuDoubleUpdates) {
  for (double range_max : {10.0, 40.0}) {
    SCOPED_TRACE("range_max " + std::to_string(range_max));
    MapperParams params;
    params.resolution = 0.05;
    params.range_max = range_max;
    ScanBatch batch;
    const std::vector<float> ranges(4, 0.05f);
    batch.add_scan(0.0, 0.0, 0.0, 0.0, 1e308, ranges.data(), 4, 1);
    batch.add_scan(0.1, 0.0, 0.0, 0.0, 1e308, ranges.data(), 4, 2);
    const GridGeometry geo = size_grid(batch, params);
    MapStats want_stats, got_stats;
    const std::vector<float> want = render_grid(*make_renderer("cpu_double"), batch, params, geo, &want_stats);
    const std::vector<float> got = render_grid(*make_renderer("cpu_float"), batch, params, geo, &got_stats);
    size_t differ = 0;
    for (size_t i = 0; i < want.size(); ++i)
      differ += (want[i] != egrid::kUnknown) != (got[i] != egrid::kUnknown);
    EXPECT_EQ(differ, 0u);
    EXPECT_EQ(got_stats.cell_updates, want_stats.cell_updates);
    EXPECT_GT(want_stats.cell_updates, 0u);
  }
}

// Two clusters of short scans at opposite corners of a grid made for a
// drive between them: the sums' box spans both, most of it reached by
// neither. One call gives, cell for cell, the bytes of each cluster's call
// alone, also on a renderer whose last call summed over the whole box (no
// value of an earlier call is read again).
TEST(CpuFloat, ClustersFarApartGiveTheBytesOfEachAlone) {
  const testing_support::CornerClusters corners(testing_support::test_seed(), 12);
  const ScanBatch &a = corners.a, &b = corners.b, &drive = corners.drive;
  const MapperParams &params = corners.params;
  const GridGeometry &geo = corners.geo;
  ScanBatch both;
  both.append(a);
  both.append(b);
  const std::unique_ptr<Renderer> reused = make_renderer("cpu_float");
  MapStats wide_stats;
  render_grid(*reused, drive, params, geo, &wide_stats);
  ASSERT_GT(wide_stats.cell_updates, 1000000u) << "the drive must leave sums all over the box";
  const std::vector<float> got = render_grid(*reused, both, params, geo);
  const std::vector<float> only_a = render_grid(*make_renderer("cpu_float"), a, params, geo);
  const std::vector<float> only_b = render_grid(*make_renderer("cpu_float"), b, params, geo);
  const std::vector<float> oracle = render_grid(*make_renderer("cpu_double"), both, params, geo);
  size_t known = 0, differ = 0;
  for (size_t i = 0; i < got.size(); ++i) {
    ASSERT_FALSE(only_a[i] != egrid::kUnknown && only_b[i] != egrid::kUnknown) << "the clusters must not meet";
    const float want = only_a[i] != egrid::kUnknown ? only_a[i] : only_b[i];
    known += want != egrid::kUnknown;
    if (std::memcmp(&want, &got[i], sizeof(float)) != 0 && ++differ <= 5)
      ADD_FAILURE() << "cell " << i << ": alone " << want << ", together " << got[i] << ", oracle " << oracle[i];
    differ += (oracle[i] != egrid::kUnknown) != (got[i] != egrid::kUnknown);
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(known, 1000u);
  EXPECT_LT(known * 20, got.size()) << "the clusters must reach a small part of the box";
}

// A full render sums in the grid's own cells (apply_to_reset); a call on a
// grid already written sums in a scratch and merges (apply_to). On a grid
// of unknown cells the two give the same bytes: an empty call first
// completes the reset, so the whole log goes the scratch's way.
TEST(CpuFloat, TheScratchAndTheGridsOwnCellsGiveTheSameBytes) {
  const testing_support::CornerClusters corners(testing_support::test_seed(), 12);
  for (const ScanBatch *scans : {&corners.drive, &corners.a}) {
    const std::vector<float> in_grid = render_grid(*make_renderer("cpu_float"), *scans, corners.params, corners.geo);
    const std::unique_ptr<Renderer> r = make_renderer("cpu_float");
    r->reset(corners.geo, corners.params);
    r->apply(*scans, 0, 0, nullptr);
    MapStats stats;
    r->apply(*scans, 0, scans->num_scans(), &stats);
    const std::vector<float> scratch = r->read(GridWindow{0, 0, corners.geo.size_x, corners.geo.size_y});
    ASSERT_GT(stats.cell_updates, 1000u);
    const size_t i = testing_support::first_difference(in_grid, scratch);
    EXPECT_EQ(i, in_grid.size()) << "cell " << i << ": in the grid " << in_grid[i] << ", by the scratch " << scratch[i];
  }
}

}  // namespace
}  // namespace vasco
