// pose_match.h — how a pose file's poses (pose_file.h) are matched to a
// log's scans: in order, by vertex id, or by timestamp.
//
//   vasco::PoseFile f = vasco::read_pose_file("after_loop_closure.g2o");
//   vasco::PoseMatch m = vasco::match_poses(f, n, scan_stamps, "run.log", scan_lines, {});
//   // m.pose[s] is scan s's new pose where m.matched[s]
#ifndef VASCO_GPU_PIPELINE_POSE_MATCH_H
#define VASCO_GPU_PIPELINE_POSE_MATCH_H

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "vasco_gpu/pipeline/pose_file.h"

namespace vasco {

enum class PoseMatching {
  Auto,       // Timestamp when the file has stamps, else Order
  Order,      // pose i -> scan i; the counts must agree
  Id,         // g2o: vertex id -> the scan index given by id_map (id_map empty: the id is the scan index)
  Timestamp,  // by the scans' stamps (below)
};

// "auto", "order", "id", "time" (what --pose-match takes); Error(Usage) otherwise.
PoseMatching pose_matching_from_name(const std::string &name);

struct PoseMatchOptions {
  PoseMatching matching = PoseMatching::Auto;
  // Timestamp matching. A scan whose stamp equals a pose's stamp takes that
  // pose unchanged (bit for bit). A stamp between two poses at most
  // `max_gap` seconds apart takes their interpolation (linear in x, y; the
  // shorter arc in theta), however far it is from either. A stamp outside
  // the trajectory (before the first pose, after the last) or in a gap
  // wider than `max_gap` takes the nearest pose unchanged when that is at
  // most `tolerance` seconds away; otherwise the scan has no pose.
  double tolerance = 0.1;
  // 5 s: a SLAM back end's keyframes come every 0.5 to 1 s while the robot
  // moves, and Cartographer's motion filter inserts a node at least every
  // 5 s even while it stands still (max_time_seconds), so 5 s takes every
  // keyframe trajectory of a moving or resting robot with room to spare.
  // A wider gap is a hole in the trajectory (tracking lost, a recorder
  // paused): drawing scans along the chord across it would put them
  // metres off, so it is refused unless asked for. +inf: any gap.
  double max_gap = 5.0;
  // A scan with no pose: an error naming it (false), or left out and counted (true).
  bool skip_unmatched = false;
  // Id matching: vertex id -> scan index (0-based); empty: identity.
  std::vector<std::pair<long, long>> id_map;
};

struct PoseMatch {
  std::vector<Pose2> pose;       // one per scan (unset where !matched)
  std::vector<uint8_t> matched;  // 1 where the scan got a pose
  uint64_t unmatched = 0;        // scans without one (only when skip_unmatched)
  uint64_t interpolated = 0;     // scans whose pose was interpolated (timestamp matching)
  uint64_t nearest = 0;          // scans outside the trajectory or a wide gap that took the pose within tolerance
  PoseMatching used = PoseMatching::Order;
};

// Matches the file's poses to `num_scans` scans whose stamps are
// `scan_stamps` (ipc timestamps; may be empty unless matching by time).
// `scan_source` and `scan_lines` (one per scan, may be empty) name a scan in
// errors ("intel.log line 812 (scan 403, stamp 1083.25)"). Throws
// carmen::FileError naming the pose file for counts that do not agree
// (Order), an id with no scan (Id), a scan without a pose (unless
// skip_unmatched; the message says how far the scan is from the poses and
// which limit that exceeds), and a file without stamps matched by time;
// Error(Usage) for a tolerance or max_gap that is negative or NaN (or an
// infinite tolerance).
PoseMatch match_poses(const PoseFile &file, size_t num_scans, const std::vector<double> &scan_stamps,
                      const std::string &scan_source, const std::vector<long> &scan_lines,
                      const PoseMatchOptions &options);

}  // namespace vasco

#endif  // VASCO_GPU_PIPELINE_POSE_MATCH_H
