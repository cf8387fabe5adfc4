// pose_file.h — poses from SLAM back ends, for re-rendering a log with the
// poses an optimizer produced: a TUM trajectory, a g2o graph's VERTEX_SE2
// vertices, or another CARMEN log's laser poses. How they are matched to a
// log's scans is pose_match.h.
//
//   vasco::PoseFile f = vasco::read_pose_file("after_loop_closure.g2o");
#ifndef VASCO_GPU_PIPELINE_POSE_FILE_H
#define VASCO_GPU_PIPELINE_POSE_FILE_H

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "vasco_gpu/pose_series.h"

namespace vasco {

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

// Reads "id scan" pairs (one per line, '#' comments) for matching g2o
// vertices to scans by id (pose_match.h). Throws carmen::FileError naming
// the file and line.
std::vector<std::pair<long, long>> read_pose_id_map(const std::string &path);

}  // namespace vasco

#endif  // VASCO_GPU_PIPELINE_POSE_FILE_H
