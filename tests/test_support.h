// Helpers shared by the tests: bundled logs and running a backend on them.
#ifndef VASCO_TESTS_TEST_SUPPORT_H
#define VASCO_TESTS_TEST_SUPPORT_H

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "carmen_compat/occupancy_grid.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/renderer.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/pipeline/log_scans.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {
namespace testing_support {

inline std::string bundled_log(const std::string &name) { return std::string(VASCO_LOGS_DIR) + "/" + name; }

struct LoadedLog {
  ScanBatch batch;
  GridGeometry geo;
};

inline LoadedLog load_log(const std::string &path, const MapperParams &params) {
  LoadedLog l;
  LogLoadStats stats;
  l.batch = load_scans(path, params, carmen::LogReaderOptions{}, &stats);
  l.geo = size_grid(l.batch, params);
  return l;
}

// Two clusters of short scans at opposite corners of a grid made for a
// drive between them (params: 0.05 m, range_max 20). Every batch starts at
// one pose (the grid's cells are placed from the first scan's): b's with a
// scan there whose beams are all unused, as is the drive's first.
struct CornerClusters {
  ScanBatch a, b, drive;
  MapperParams params;
  GridGeometry geo;

  CornerClusters(unsigned seed, int scans_per_cluster) {
    params.resolution = 0.05;
    params.range_max = 20.0;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> jitter(-0.2, 0.2), ang(-M_PI, M_PI);
    std::uniform_real_distribution<float> r(0.3f, 1.5f);
    const auto cluster = [&](double cx, double cy, ScanBatch *into, int stamp) {
      for (int s = 0; s < scans_per_cluster; ++s) {
        std::vector<float> ranges(91);
        for (float &v : ranges) v = r(rng);
        into->add_scan(cx + jitter(rng), cy + jitter(rng), ang(rng), -M_PI / 2, M_PI / 90, ranges.data(), 91,
                       stamp + s);
      }
    };
    const std::vector<float> unused(91, std::nanf(""));
    cluster(-12.0, -12.0, &a, 1);
    b.add_scan(a.x[0], a.y[0], a.theta[0], -M_PI / 2, M_PI / 90, unused.data(), 91, 99);
    cluster(12.0, 12.0, &b, 100);
    const std::vector<float> far(181, 19.0f);
    drive.add_scan(a.x[0], a.y[0], a.theta[0], -M_PI / 2, M_PI / 90, unused.data(), 91, 1);
    for (int s = 0; s <= 24; ++s)
      drive.add_scan(-12.0 + s, -12.0 + s, M_PI / 4, -M_PI / 2, M_PI / 180, far.data(), 181, s + 2);
    geo = size_grid(drive, params);
  }
};

// Random scans with odd ranges: NaN, +-inf, negative, >= 50, 49.99.
inline ScanBatch random_batch(std::mt19937 &rng, int num_scans, double spread) {
  std::uniform_real_distribution<double> pos(-spread, spread), ang(-M_PI, M_PI), rr(0, 12);
  std::uniform_int_distribution<int> odd(0, 40), nbeams(1, 400);
  ScanBatch batch;
  for (int s = 0; s < num_scans; ++s) {
    const int n = nbeams(rng);
    std::vector<float> r(n);
    for (auto &v : r) {
      switch (odd(rng)) {
        case 0: v = NAN; break;
        case 1: v = INFINITY; break;
        case 2: v = -INFINITY; break;
        case 3: v = -static_cast<float>(rr(rng)) / 4; break;
        case 4: v = 50.0f + static_cast<float>(rr(rng)); break;
        case 5: v = 49.99f; break;
        case 6: v = 50.0f; break;
        default: v = static_cast<float>(rr(rng));
      }
    }
    batch.add_scan(pos(rng), pos(rng), ang(rng), ang(rng) / 2, 0.01 + 0.02 * (s % 3), r.data(), n, s + 1);
  }
  return batch;
}

// Index of the first cell whose bits differ, or a.size() if none does.
inline size_t first_difference(const std::vector<float> &a, const std::vector<float> &b) {
  for (size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0) return i;
  return a.size();
}

// Fails the test unless `got` is bit-identical to the oracle's `ref`, naming
// the first differing cell.
inline void expect_bit_identical(const std::vector<float> &ref, const std::vector<float> &got,
                                 const GridGeometry &geo, const std::string &what) {
  ASSERT_EQ(ref.size(), got.size());
  const size_t i = first_difference(ref, got);
  if (i < ref.size()) {
    std::ostringstream msg;
    msg.precision(9);
    msg << "first difference at cell (" << i / geo.size_y << ", " << i % geo.size_y << "): oracle "
        << ref[i] << ", " << what << " " << got[i];
    ADD_FAILURE() << msg.str();
  }
}

// Fails the test unless the session's finish as OccupancyGrid data
// (Mapper::finish_occupancy, converted where the grid is) is the host's
// conversion (carmen_compat/occupancy_grid.h, tested against map_server's
// reading of our pictures) of its finish(), with the same frame, for both
// modes and two pairs of thresholds; `out` is asked once, for the map's
// cells.
inline void expect_occupancy_of_finish(const Mapper &m, int ds, int border, const std::string &what) {
  const FinishedMap ref = m.finish(ds, border);
  carmen::GridMap grid = carmen::GridMap::filled(ref.size_x, ref.size_y, ref.resolution);
  grid.cells = ref.cells;
  carmen::MapServerOptions opts[3];
  opts[1].free_thresh = 0.25;
  opts[1].occupied_thresh = 0.5;
  opts[2].mode = carmen::PgmMode::Raw;
  for (const carmen::MapServerOptions &o : opts) {
    const std::vector<int8_t> want = carmen::occupancy_grid_data(grid, o);
    if (&o == &opts[0]) {  // a map with cells of every kind, or the comparison would prove little
      EXPECT_TRUE(std::count(want.begin(), want.end(), 100) > 0 && std::count(want.begin(), want.end(), 0) > 0 &&
                  std::count(want.begin(), want.end(), -1) > 0)
          << what << ": a map without occupied, free and unknown cells";
    }
    std::vector<int8_t> got;
    int asked = 0;
    const FinishedMap f = m.finish_occupancy(carmen::occupancy_values(o), [&](size_t n) {
      ++asked;
      got.assign(n, int8_t(42));
      return got.data();
    }, ds, border);
    const std::string label = what + " downsample " + std::to_string(ds) + " mode " +
                              (o.mode == carmen::PgmMode::Raw ? "raw" : "trinary") + " free " +
                              std::to_string(o.free_thresh);
    EXPECT_EQ(asked, 1) << label;
    EXPECT_TRUE(f.cells.empty()) << label;
    EXPECT_EQ(f.size_x, ref.size_x) << label;
    EXPECT_EQ(f.size_y, ref.size_y) << label;
    EXPECT_EQ(f.min_x, ref.min_x) << label;
    EXPECT_EQ(f.min_y, ref.min_y) << label;
    EXPECT_EQ(f.resolution, ref.resolution) << label;
    EXPECT_EQ(f.downsample, ref.downsample) << label;
    ASSERT_EQ(got.size(), want.size()) << label;
    size_t differ = 0, first = got.size();
    for (size_t i = 0; i < got.size(); ++i)
      if (got[i] != want[i] && differ++ == 0) first = i;
    EXPECT_EQ(differ, 0u) << label << ": first at data index " << first;
  }
}

}  // namespace testing_support
}  // namespace vasco

#endif  // VASCO_TESTS_TEST_SUPPORT_H
