// Planar poses along a trajectory; see pose_series.h.
#include "vasco_gpu/pose_series.h"

#include <algorithm>
#include <numeric>

#include "vasco_gpu/internal/se2.h"

namespace vasco {

bool strictly_ascending(const int64_t *stamps, size_t n) {
  for (size_t i = 1; i < n; ++i)
    if (!(stamps[i - 1] < stamps[i])) return false;
  return true;
}

void sort_series(std::vector<int64_t> &stamps, std::vector<Pose2> &poses) {
  if (strictly_ascending(stamps.data(), stamps.size())) return;
  std::vector<size_t> order(stamps.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return stamps[a] < stamps[b]; });
  std::vector<int64_t> s;
  std::vector<Pose2> p;
  s.reserve(order.size());
  p.reserve(order.size());
  for (size_t k = 0; k < order.size(); ++k) {
    const bool repeated = k + 1 < order.size() && stamps[order[k + 1]] == stamps[order[k]];
    if (repeated) continue;  // a later sample of this stamp follows (a stable sort keeps their order)
    s.push_back(stamps[order[k]]);
    p.push_back(poses[order[k]]);
  }
  stamps.swap(s);
  poses.swap(p);
}

SeriesPlace pose_at_stamp(const PoseSeriesView &series, int64_t t, int64_t max_gap_ns, Pose2 &pose) {
  const int64_t *end = series.stamps + series.size;
  const int64_t *it = std::lower_bound(series.stamps, end, t);
  if (it != end && *it == t) {
    pose = series.poses[it - series.stamps];
    return SeriesPlace::Exact;
  }
  if (it == series.stamps || it == end) return SeriesPlace::Outside;
  const size_t hi = size_t(it - series.stamps), lo = hi - 1;
  // differences of stamps within one trajectory: a bag's span is far below 2^63 ns
  const int64_t gap = series.stamps[hi] - series.stamps[lo];
  if (gap > max_gap_ns) return SeriesPlace::InGap;
  const double u = double(t - series.stamps[lo]) / double(gap);
  pose = pose_between(series.poses[lo], series.poses[hi], u);
  return SeriesPlace::Between;
}

}  // namespace vasco
