// log_input.h — everything log2map (and the golden harness) needs before a
// backend runs, by DESIGN §3: parameters from their three sources, the laser
// scans of the log, the selected run of them, and the grid they are mapped on.
//
// Parameter precedence, the same for every key: command line > ini file >
// the log's own PARAM lines > vasco's defaults. vasco_first_scan and
// vasco_num_scans follow it too: every laser message is read first and the
// run is selected once the log's PARAM lines are known.
#ifndef VASCO_GPU_PIPELINE_LOG_INPUT_H
#define VASCO_GPU_PIPELINE_LOG_INPUT_H

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "vasco_gpu/grid.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/pipeline/log_scans.h"
#include "vasco_gpu/pipeline/pose_match.h"
#include "vasco_gpu/pipeline/session_align.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

// One more input of a map made from several sessions (several robots or
// days in one place): its scans follow the first log's, each pose taken into
// the shared frame by `transform` (the identity when the sessions already
// share one), or with auto_transform by aligning the session's map to the
// map of the sessions before it (session_align.h; `hint`: search only near
// a guess).
struct SessionInput {
  std::string path;
  Pose2 transform;
  bool auto_transform = false;
  std::optional<AlignHint> hint;
};

// Where the scans' poses come from when not from the inputs themselves: a
// pose file of a SLAM back end (pose_file.h, pose_match.h), matched to the scans of the
// whole input before vasco_first_scan / vasco_num_scans select.
struct PoseSource {
  std::string file;  // empty: the inputs' own laser poses
  PoseFileFormat format = PoseFileFormat::Auto;
  PoseMatchOptions match;
  std::string id_map_file;  // "id scan" pairs for PoseMatching::Id
  // The poses are of the laser (false) or of the robot (true): a robot pose
  // is taken to the laser by the mount, given here (has_mount) or read from
  // each scan (ROBOTLASER1 lines and bags carry one; FLASER lines do not).
  bool robot_frame = false;
  bool has_mount = false;
  Pose2 mount;  // the laser in the robot's frame
};

// A log's scans with what the pose sources need of each: its timestamp and
// (where the input says) the laser's mount on the robot. What load_log_input
// reads from CARMEN logs, and what a bag reader hands over.
struct StampedScans {
  ScanBatch batch;
  std::vector<double> stamps;     // one per scan (NaN where unknown)
  std::vector<Pose2> mounts;      // one per scan where has_mount[s]
  std::vector<uint8_t> has_mount;
  uint64_t unposed = 0;           // scans the reader left out for want of a pose (--skip-unposed)
  // Appends `more` with every pose taken into the shared frame by `transform`.
  void append(StampedScans &&more, const Pose2 &transform);
  // Keeps the scans where keep[s] (what skip_unmatched leaves).
  void keep_only(const std::vector<uint8_t> &keep);
};

// ROS's usual map cell in metres (map_saver's examples, slam_toolbox's and
// cartographer's occupancy grid node's default): the default map resolution
// of inputs that come from ROS (bags, the ROS 2 node), where CARMEN logs keep
// CARMEN's keys (0.025 x 4 = 0.1).
inline constexpr double kRosMapResolution = 0.05;

struct LogInputOptions {
  std::string log;                               // .log, .clf, gzipped if .gz
  Pose2 transform;                               // of `log` into the shared frame (identity: as read)
  std::vector<SessionInput> more_logs;           // further sessions mapped into the same grid
  SessionAlignOptions align;                     // how "@auto" sessions are aligned
  PoseSource poses;
  std::string param_file;                        // carmen.ini; empty: none
  std::string robot;                             // robot section of the ini
  std::map<std::string, std::string> overrides;  // vasco_KEY -> value (command line)
  // The written map's cell in metres (--resolution), applied over the keys
  // by MapperParams::set_map_resolution (vasco_downsample stays where the
  // ini, the log or an override sets it). default_map_resolution: a tool's
  // own default (bag2map: 0.05), taken when map_resolution is not given and
  // nothing sets vasco_resolution; 0: none (CARMEN's keys alone).
  std::optional<double> map_resolution;
  double default_map_resolution = 0;
  bool lenient = false;                          // skip bad lines instead of stopping
  std::function<void(uint64_t, uint64_t)> progress;  // (bytes read, file size)
  // Bytes the scans and PARAM lines kept from the log may take (0: no limit),
  // counted while the log is read: the message that passes it is refused
  // (FileError naming the line, ErrorCode::OutOfMemory) before the rest is
  // read. budget_option: how the user raises it, as the error names it.
  uint64_t memory_budget = 0;
  std::string budget_option = "--max-memory";
};

struct LogInput {
  MapperParams params;                // validated
  ScanBatch batch;                    // the selected scans, in log order
  std::vector<double> stamps;         // their timestamps (NaN where unknown)
  uint64_t posed_from_file = 0;       // scans whose pose came from options.poses
  uint64_t unposed_skipped = 0;       // scans left out for want of a pose (skip_unmatched)
  LogLoadStats load;                  // counts of the whole log
  GridGeometry geo;                   // DESIGN §3 step 2 (size_grid), from the selected scans: the
                                      // frame a Mapper's first insert of `batch` takes (use the
                                      // Mapper's frame() once it has mapped them)
  std::vector<std::string> warnings;  // unknown vasco_* keys and the like
  std::vector<AddedSession> added_sessions;  // one per more_logs, in order: the transforms mapped
};

// Reads the parameters and the log. Throws carmen::FileError naming the file
// (and line) for bad input: an unreadable or malformed log or ini, a bad
// parameter value, no scans in the selected run, poses too far apart.
// With more_logs, every input is read in turn; their PARAM lines apply in
// that order, as if the logs were one file, and the frame is that of the
// combined scans: on an exact backend the map equals that of one log holding
// every scan in that order. Sessions with auto_transform are aligned once
// every log is read (session_align.h), in order; one the alignment refuses
// throws a carmen::FileError naming it.
LogInput load_log_input(const LogInputOptions &options);

// The same from scans read elsewhere (a ROS bag): the parameters come from
// options' ini and overrides (a bag has no PARAM lines), options.poses
// applies, options.log names the source in errors and options.more_logs
// must be empty (the caller appends further sessions to `scans` itself).
LogInput log_input_from_scans(StampedScans scans, const LogInputOptions &options);

// The same for several sessions read elsewhere: more[i] holds the scans of
// options.more_logs[i] in that session's own frame; each is appended at its
// transform, given or found by the alignment ("@auto") as load_log_input
// does.
LogInput log_input_from_sessions(StampedScans first, std::vector<StampedScans> more, const LogInputOptions &options);

// Reads a CARMEN log's scans with their stamps and mounts (every laser
// message; no selection), counting into *stats.
StampedScans read_stamped_scans(const std::string &path, const LogInputOptions &options, LogLoadStats *stats);

}  // namespace vasco

#endif  // VASCO_GPU_PIPELINE_LOG_INPUT_H
