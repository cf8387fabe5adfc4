// pose_series.h — planar poses along a trajectory: the planar pose, and the
// pose at a nanosecond stamp among a trajectory's poses (a bag's pose topic,
// the node's Path), between two of them by the --poses interpolation
// (internal/se2.h pose_between, written once for pose files, bags' pose
// topics and the live node's Path).
//
//   vasco::Pose2 p;
//   if (vasco::pose_at_stamp(series, scan_ns, max_gap_ns, p) <= vasco::SeriesPlace::Between) ...
#ifndef VASCO_GPU_POSE_SERIES_H
#define VASCO_GPU_POSE_SERIES_H

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vasco {

// A planar pose: x, y in metres, theta in radians.
struct Pose2 {
  double x = 0, y = 0, theta = 0;
};

// Where a stamp lies in a trajectory.
enum class SeriesPlace : uint8_t {
  Exact = 0,    // on a pose's stamp: that pose, no arithmetic
  Between = 1,  // between two poses at most max_gap_ns apart: pose_between of them
  Outside = 2,  // before the first pose or after the last
  InGap = 3,    // between two poses more than max_gap_ns apart
};

// A trajectory on nanosecond stamps: `stamps` strictly ascending, one pose
// each (sort_series makes one of samples in any order).
struct PoseSeriesView {
  const int64_t *stamps = nullptr;
  const Pose2 *poses = nullptr;
  size_t size = 0;
};

// Whether stamps[0..n) ascend strictly (a trajectory's usual order).
bool strictly_ascending(const int64_t *stamps, size_t n);

// Samples recorded in any order sorted by stamp, one a stamp: of samples
// with the same stamp, the one recorded last.
void sort_series(std::vector<int64_t> &stamps, std::vector<Pose2> &poses);

// The pose at stamp t (see SeriesPlace); `pose` is set for Exact and Between
// only. The fraction is taken on the integer stamps, (t - t0) / (t1 - t0) in
// double.
SeriesPlace pose_at_stamp(const PoseSeriesView &series, int64_t t, int64_t max_gap_ns, Pose2 &pose);

}  // namespace vasco

#endif  // VASCO_GPU_POSE_SERIES_H
