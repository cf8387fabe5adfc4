// Pose files of SLAM back ends (TUM, g2o, id maps) and their matching to
// scans: any input is read or refused with a carmen::Error, and every pose
// handed out is finite and, when interpolated, between its two neighbours.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "carmen_compat/error.h"
#include "fuzz_support.h"
#include "vasco_gpu/pipeline/pose_match.h"

namespace {

void check_match(const vasco::PoseFile &file, vasco::PoseMatching how) {
  // Scan stamps across the file's span and beyond, some between poses.
  std::vector<double> stamps;
  for (const vasco::StampedPose &p : file.poses) {
    if (!std::isfinite(p.stamp)) continue;
    stamps.push_back(p.stamp);
    stamps.push_back(p.stamp + 0.03);
    if (stamps.size() > 64) break;
  }
  const size_t n = how == vasco::PoseMatching::Timestamp ? stamps.size() : std::min<size_t>(file.poses.size(), 64);
  vasco::PoseMatchOptions o;
  o.matching = how;
  o.skip_unmatched = true;
  o.tolerance = 0.05;
  vasco::PoseMatch m;
  try {
    m = vasco::match_poses(file, n, how == vasco::PoseMatching::Timestamp ? stamps : std::vector<double>{}, "fuzz.log",
                           {}, o);
  } catch (const carmen::Error &) {
    return;  // counts that disagree, ids out of range, two poses for one stamp
  }
  if (m.pose.size() != n || m.matched.size() != n) std::abort();
  for (size_t s = 0; s < n; ++s)
    if (m.matched[s] && !(std::isfinite(m.pose[s].x) && std::isfinite(m.pose[s].y) && std::isfinite(m.pose[s].theta)))
      std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  for (const char *suffix : {".txt", ".g2o"}) {
    fuzz::InputFile in(data, size, suffix);
    try {
      const vasco::PoseFile file = vasco::read_pose_file(in.path());
      for (const vasco::StampedPose &p : file.poses)
        if (!std::isfinite(p.pose.x) || !std::isfinite(p.pose.y) || !std::isfinite(p.pose.theta)) std::abort();
      check_match(file, vasco::PoseMatching::Order);
      check_match(file, file.has_stamps() ? vasco::PoseMatching::Timestamp : vasco::PoseMatching::Id);
    } catch (const carmen::Error &) {
    }
    try {
      vasco::read_pose_id_map(in.path());
    } catch (const carmen::Error &) {
    }
  }
  return 0;
}
