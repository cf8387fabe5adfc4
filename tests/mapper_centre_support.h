// What the tests of a fixed frame at a given centre share: fr079's scans,
// a frame centred off every scan's pose, and CARMEN's own egrid API started
// at that centre (the independent route the grids are compared with).
#ifndef VASCO_TESTS_MAPPER_CENTRE_SUPPORT_H
#define VASCO_TESTS_MAPPER_CENTRE_SUPPORT_H

#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "carmen/egrid.h"
#include "test_support.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {
namespace centre_support {

using testing_support::bundled_log;

inline MapperParams full_resolution() {
  MapperParams p;
  p.downsample = 1;
  return p;
}

// fr079's scans [a, a + n), loaded once.
inline ScanBatch fr079(long a, long n) {
  static const ScanBatch all = [] {
    LogLoadStats st;
    return load_scans(bundled_log("fr079-complete.gfs.log.gz"), full_resolution(), carmen::LogReaderOptions{}, &st)
        .select(0, 400);
  }();
  return all.select(a, n);
}

// A frame of 800 x 700 cells centred 2.3456 m east and 1.789 m south of
// fr079's first scan (on no scan's pose, off the cell lattice), heading
// `theta_offset`.
inline GridGeometry centred_frame(double theta_offset = 0.7) {
  const ScanBatch first = fr079(0, 1);
  GridGeometry f;
  f.size_x = 800;
  f.size_y = 700;
  f.resolution = full_resolution().resolution;
  f.theta_offset = theta_offset;
  f.x0 = first.x[0] + 2.3456;
  f.y0 = first.y[0] - 1.789;
  f.centre_given = true;
  return f;
}

// CARMEN's egrid API (carmen/egrid.h) with its first update a pose at the
// frame's centre heading `heading` without readings — it records the start
// pose and changes no cell — then every scan of `scans`, one call each.
inline std::vector<float> carmen_anchored(const ScanBatch &scans, const MapperParams &p,
                                          const GridGeometry &frame, double heading = 0.7) {
  evidence_grid g;
  EXPECT_EQ(carmen_mapper_initialize_evidence_grid(&g, frame.size_x, frame.size_y, p.resolution, heading, p.p_prior,
                                                   p.p_occ, p.p_emp, 0.99, p.range_sure, p.range_max, p.wall_size),
            0);
  float none = 0;
  carmen_mapper_update_evidence_grid(&g, frame.x0, frame.y0, heading, 0, &none, 0.01, 0.0);
  for (size_t s = 0; s < scans.num_scans(); ++s) {
    std::vector<float> r(scans.ranges_of(s), scans.ranges_of(s) + scans.beams_in(s));
    carmen_mapper_update_evidence_grid(&g, scans.x[s], scans.y[s], scans.theta[s], scans.beams_in(s), r.data(),
                                       scans.angle_step[s], scans.first_angle[s]);
  }
  std::vector<float> cells(static_cast<size_t>(frame.size_x) * frame.size_y);
  for (int x = 0; x < frame.size_x; ++x)
    for (int y = 0; y < frame.size_y; ++y) cells[static_cast<size_t>(x) * frame.size_y + y] = g.prob[x][y];
  carmen_mapper_free_evidence_grid(&g);
  return cells;
}

// The other route to a centred frame: the fixed frame centred on its first
// scan, fed a scan without readings at the centre (heading theta_offset)
// before `scans`. Returns that frame (centre_given off) and those scans.
inline std::pair<GridGeometry, ScanBatch> anchored_at_centre(const GridGeometry &frame, const ScanBatch &scans) {
  ScanBatch anchored;
  anchored.add_scan(frame.x0, frame.y0, frame.theta_offset, 0.0, 0.01, nullptr, 0, 0);
  anchored.append(scans);
  GridGeometry on_first_scan = frame;
  on_first_scan.centre_given = false;
  return {on_first_scan, anchored};
}

}  // namespace centre_support
}  // namespace vasco

#endif  // VASCO_TESTS_MAPPER_CENTRE_SUPPORT_H
