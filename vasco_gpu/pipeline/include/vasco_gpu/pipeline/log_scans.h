// log_scans.h — the laser scans of a CARMEN log, read into a ScanBatch
// (DESIGN §3 step 1), and which log messages are those scans.
//
//   vasco::LogLoadStats stats;
//   vasco::ScanBatch batch = vasco::load_scans("intel.log.gz", params, {}, &stats);
#ifndef VASCO_GPU_PIPELINE_LOG_SCANS_H
#define VASCO_GPU_PIPELINE_LOG_SCANS_H

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "carmen_compat/log_reader.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

struct MapperParams;

// What reading a log produced, besides the scans.
struct LogLoadStats {
  carmen::LogStats log;          // counts, skipped and bad lines, odd ranges
  long laser_messages = 0;       // FLASER + ROBOTLASER1 lines seen
  long scans_used = 0;           // after vasco_first_scan / vasco_num_scans
  std::vector<std::pair<std::string, std::string>> params;  // PARAM lines (name, value)
  std::vector<long> param_lines;                            // their line numbers
  // Per scan kept: its ipc timestamp, and the robot's pose where the line
  // gives it in the laser pose's frame (ROBOTLASER1; FLASER's odometry
  // triple is in the odometry frame, so robot_pose_known is 0 there).
  std::vector<double> stamps;
  std::vector<carmen::Point> robot_poses;
  std::vector<uint8_t> robot_pose_known;
};

// Which log messages are the scans a map is made of (DESIGN §3 step 1): the
// front laser's lines with a laser pose, FLASER and ROBOTLASER1 (RLASER and
// ROBOTLASER2 are the rear laser's; RAWLASERn carry no pose). Written once
// here: load_scans, the log input's memory budget, the pose files' CARMEN
// logs and the Python bindings read it.
bool is_scan_message(carmen::MessageType type);
// message_type_bit of each scan message type.
uint32_t scan_message_bits();
// Their names for messages and help texts: "FLASER or ROBOTLASER1" (`joiner`
// " or ") or "FLASER and ROBOTLASER1".
std::string scan_message_names(const char *joiner = " or ");

// Reads the laser scans of a log by DESIGN §3 step 1: every FLASER and
// ROBOTLASER1 line in file order (laser pose; FLASER's configuration guessed
// from its beam count), then the contiguous subset [first_scan, first_scan +
// num_scans). `progress(done, total)` (bytes of the file) is called now and
// then when set. Throws carmen::FileError on bad input.
ScanBatch load_scans(const std::string &log_path, const MapperParams &params,
                     const carmen::LogReaderOptions &options, LogLoadStats *stats,
                     const std::function<void(uint64_t, uint64_t)> &progress = {});

}  // namespace vasco

#endif  // VASCO_GPU_PIPELINE_LOG_SCANS_H
