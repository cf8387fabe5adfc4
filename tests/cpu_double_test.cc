// The cpu_double backend against the oracle's reference loop
// (oracle::update_scan, what carmen_egrid_api.cc runs for CARMEN's C API): the backend
// takes a faster path for ordinary beams (cpu_double_backend.cc), which must
// give the same grid bytes and counts wherever it is taken or left.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "test_seed.h"
#include "test_support.h"
#include "vasco_gpu/internal/oracle.h"
#include "vasco_gpu/renderer.h"
#include "vasco_gpu/internal/sensor_params.h"

namespace vasco {
namespace {

using testing_support::random_batch;

// oracle::update_scan over scans [0, n), as carmen_egrid_api.cc drives it.
std::vector<float> reference_map(const ScanBatch &batch, const MapperParams &params, const GridGeometry &geo,
                                 MapStats *stats) {
  std::vector<float> cells(geo.num_cells(), egrid::kUnknown);
  oracle::GridFrame frame;
  frame.size_x = geo.size_x;
  frame.size_y = geo.size_y;
  frame.resolution = geo.resolution;
  frame.theta_offset = geo.theta_offset;
  const int T = params.table_size();
  std::vector<double> values;
  std::vector<double *> rows;
  if (T > 0 && T <= oracle::kMaxBuiltDistanceTable) {
    values.resize(static_cast<size_t>(T) * T);
    for (int i = 0; i < T; ++i) rows.push_back(values.data() + static_cast<size_t>(i) * T);
    oracle::fill_distance_table(rows.data(), T, params.resolution);
  }
  *stats = MapStats{};
  for (size_t s = 0; s < batch.num_scans(); ++s) {
    const auto c = oracle::update_scan(cells.data(), frame, sensor_model_of(params), params.wall_size, T,
                                       rows.empty() ? nullptr : rows.data(), batch.x[s], batch.y[s],
                                       batch.theta[s], batch.beams_in(s), batch.ranges_of(s),
                                       oracle::SteppedAngles{batch.first_angle[s], batch.angle_step[s]});
    stats->beams_used += c.beams_used;
    stats->beams_skipped += c.beams_skipped;
    stats->cell_updates += c.cell_updates;
  }
  stats->scans = batch.num_scans();
  return cells;
}

// cpu_double in one call and in three (apply's `first`), against the reference.
void check_against_reference(const ScanBatch &batch, const MapperParams &params, const GridGeometry &geo) {
  MapStats ref_stats, st;
  const std::vector<float> ref = reference_map(batch, params, geo, &ref_stats);
  auto renderer = make_renderer("cpu_double");
  const std::vector<float> got = render_grid(*renderer, batch, params, geo, &st);
  testing_support::expect_bit_identical(ref, got, geo, "cpu_double");
  EXPECT_EQ(ref_stats.beams_used, st.beams_used);
  EXPECT_EQ(ref_stats.beams_skipped, st.beams_skipped);
  EXPECT_EQ(ref_stats.cell_updates, st.cell_updates);

  const size_t n = batch.num_scans(), a = n / 3, b = 2 * n / 3;
  renderer->reset(geo, params);
  renderer->apply(batch, 0, a, nullptr);
  renderer->apply(batch, a, b, nullptr);
  renderer->apply(batch, b, n, nullptr);
  const std::vector<float> parts = renderer->read(GridWindow{0, 0, geo.size_x, geo.size_y});
  testing_support::expect_bit_identical(ref, parts, geo, "cpu_double in three calls");
}

struct ParamCase {
  const char *what;
  double resolution, range_sure, range_max, p_prior, p_occ, p_emp;
  double shrink;  // grid size factor: below 1, scan starts and beams leave the grid
};

TEST(CpuDouble, RandomScansMatchTheOracleLoop) {
  const unsigned seed = testing_support::test_seed();
  SCOPED_TRACE("random seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  const ParamCase cases[] = {
      {"defaults", 0.025, 5.0, 10.0, 0.5, 0.55, 0.45, 1.0},
      {"coarse", 0.05, 5.0, 10.0, 0.5, 0.55, 0.45, 1.0},
      {"shrunken grid", 0.1, 5.0, 10.0, 0.5, 0.55, 0.45, 0.3},
      {"odd resolution and evidence", 0.037, 1.5, 4.0, 0.3, 0.9, 0.2, 1.0},
      {"no constant zone (sure 0)", 0.05, 0.0, 6.0, 0.5, 0.7, 0.3, 1.0},
      {"no annulus (sure = max)", 0.05, 3.0, 3.0, 0.6, 0.8, 0.1, 0.5},
      {"fine", 0.013, 0.5, 2.0, 0.5, 0.55, 0.45, 1.0},
      {"one-cell table", 0.5, 0.25, 0.6, 0.5, 0.55, 0.45, 1.0},
      {"empty table (max < resolution)", 0.5, 0.1, 0.4, 0.5, 0.55, 0.45, 1.0},
  };
  for (const ParamCase &pc : cases) {
    SCOPED_TRACE(pc.what);
    MapperParams params;
    params.resolution = pc.resolution;
    params.range_sure = pc.range_sure;
    params.range_max = pc.range_max;
    params.p_prior = pc.p_prior;
    params.p_occ = pc.p_occ;
    params.p_emp = pc.p_emp;
    const ScanBatch batch = random_batch(rng, 60, 4);
    GridGeometry geo = size_grid(batch, params);
    geo.size_x = std::max(1, static_cast<int>(geo.size_x * pc.shrink));
    geo.size_y = std::max(1, static_cast<int>(geo.size_y * pc.shrink * 0.8));
    check_against_reference(batch, params, geo);
  }
}

// Beams along the axes and diagonals whose ranges fall on cell distances
// (multiples of the resolution, and those +- 1 ulp): where d < range, d < sure
// and d < max turn, which the fast path decides on squared cell distances.
TEST(CpuDouble, RangesOnCellDistancesMatchTheOracleLoop) {
  MapperParams params;
  params.resolution = 0.05;
  params.range_sure = 1.0;
  params.range_max = 2.0;
  ScanBatch batch;
  int line = 1;
  for (int k = 0; k <= 45; ++k) {
    const float base = static_cast<float>(k * params.resolution);
    for (float r : {base, std::nextafter(base, 0.0f), std::nextafter(base, 100.0f)}) {
      const std::vector<float> ranges(8, r);
      batch.add_scan(0.01 * (k % 3), -0.02 * (k % 2), 0.0, 0.0, M_PI / 4, ranges.data(), 8, line++);
    }
  }
  check_against_reference(batch, params, size_grid(batch, params));
}

// A table above the built distance table's limit (oracle::kMaxBuiltDistanceTable)
// and an annulus too large to tabulate: distances and evidence on the fly.
TEST(CpuDouble, LargeTablesMatchTheOracleLoop) {
  const unsigned seed = testing_support::test_seed();
  SCOPED_TRACE("random seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  MapperParams params;
  params.resolution = 0.002;
  params.range_sure = 5.0;
  params.range_max = 8.5;  // 4250 entries per axis
  ASSERT_GT(params.table_size(), oracle::kMaxBuiltDistanceTable);
  const ScanBatch batch = random_batch(rng, 4, 0.5);
  GridGeometry geo = size_grid(batch, params);
  geo.size_x = 2500;  // beams leave the grid: keeps the test's memory small
  geo.size_y = 1500;
  check_against_reference(batch, params, geo);
}

// Many scans from one pose until cells saturate; a single scan.
TEST(CpuDouble, SaturatedCellsAndSingleScanMatchTheOracleLoop) {
  const unsigned seed = testing_support::test_seed();
  SCOPED_TRACE("random seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  MapperParams params;
  params.resolution = 0.05;
  params.p_occ = 0.95;
  params.p_emp = 0.05;
  const ScanBatch still = random_batch(rng, 200, 0.0);
  check_against_reference(still, params, size_grid(still, params));
  const ScanBatch one = random_batch(rng, 1, 0);
  check_against_reference(one, params, size_grid(one, params));
}

}  // namespace
}  // namespace vasco
