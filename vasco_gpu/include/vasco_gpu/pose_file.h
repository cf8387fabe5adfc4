// pose_file.h — poses from SLAM back ends, for re-rendering a log with the
// poses an optimizer produced: a TUM trajectory, a g2o graph's VERTEX_SE2
// vertices, or another CARMEN log's laser poses; and how they are matched
// to a log's scans (in order, by vertex id, or by timestamp).
//
//   vasco::PoseFile f = vasco::read_pose_file("after_loop_closure.g2o");
//   vasco::PoseMatch m = vasco::match_poses(f, n, scan_stamps, "run.log", scan_lines, {});
//   // m.pose[s] is scan s's new pose where m.matched[s]
#ifndef VASCO_GPU_POSE_FILE_H
#define VASCO_GPU_POSE_FILE_H

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace vasco {

// A planar pose: x, y in metres, theta in radians.
struct Pose2 {
  double x = 0, y = 0, theta = 0;
};

enum class PoseFileFormat {
  Auto,       // by extension: .g2o -> G2o; .log, .clf (also .gz) -> CarmenLog; anything else -> Tum
  Tum,        // "t x y z qx qy qz qw" per line; '#' comments; yaw from the quaternion
  G2o,        // "VERTEX_SE2 id x y theta" lines; every other line is ignored
  CarmenLog,  // the laser poses of a CARMEN log's FLASER / ROBOTLASER1 lines, with their ipc timestamps
};

// "auto", "tum", "g2o", "carmen" (what --pose-format takes); Error(Usage) otherwise.
PoseFileFormat pose_file_format_from_name(const std::string &name);
const char *pose_file_format_name(PoseFileFormat format);

struct StampedPose {
  double stamp = 0;  // seconds; NaN where the format has none (g2o)
  long id = -1;      // g2o vertex id; -1 elsewhere
  long line = 0;     // line of the file the pose came from (for messages)
  Pose2 pose;
};

struct PoseFile {
  std::string path;
  PoseFileFormat format = PoseFileFormat::Tum;
  std::vector<StampedPose> poses;  // in file order
  bool has_stamps() const { return format != PoseFileFormat::G2o; }
};

// Reads a pose file. Throws carmen::FileError naming the file and line for
// anything malformed: too few fields, a field that is not a number, a value
// that is not finite, a zero or non-finite quaternion, a repeated g2o id, no
// poses at all; ErrorCode::Io for a file that cannot be read. Stamps may go
// back (real logs' do now and then): matching by time sorts them, and
// refuses a stamp given twice with two different poses.
// What a pose file may take in memory, counted while it is read (0: no
// limit): the pose that passes it is refused (FileError at its line,
// ErrorCode::OutOfMemory) before the rest is read. budget_option: how the
// user raises it, as the error names it (log2map: --max-memory).
struct PoseReadLimits {
  uint64_t memory_budget = 0;
  std::string budget_option = "PoseReadLimits::memory_budget";
};

PoseFile read_pose_file(const std::string &path, PoseFileFormat format = PoseFileFormat::Auto,
                        const PoseReadLimits &limits = {});

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

// Reads "id scan" pairs (one per line, '#' comments) for Id matching.
// Throws carmen::FileError naming the file and line.
std::vector<std::pair<long, long>> read_pose_id_map(const std::string &path);

// Rigid-body algebra on planar poses, as the log tools use it.
// compose(a, b): b expressed in a's frame, taken to the frame a is in.
Pose2 compose(const Pose2 &a, const Pose2 &b);
// inverse(a): compose(a, inverse(a)) is the identity (up to rounding).
Pose2 inverse(const Pose2 &a);
// theta of a unit quaternion's rotation about z (the yaw), for TUM and ROS.
double yaw_of_quaternion(double qx, double qy, double qz, double qw);

}  // namespace vasco

#endif  // VASCO_GPU_POSE_FILE_H
