// scan_batch.h — the laser scans of a log, as a structure of arrays: what
// every backend consumes (and what the CUDA backend uploads once).
#ifndef VASCO_GPU_SCAN_BATCH_H
#define VASCO_GPU_SCAN_BATCH_H

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "carmen_compat/log_reader.h"

namespace vasco {

struct MapperParams;

struct ScanBatch {
  // Per scan: the laser pose (double, as parsed) and its beam geometry.
  std::vector<double> x, y, theta;
  std::vector<double> first_angle;   // angle of beam 0 relative to theta
  std::vector<double> angle_step;    // added after every beam
  std::vector<uint64_t> beam_offset; // scan s owns beams [beam_offset[s], beam_offset[s+1])
  std::vector<long> line;            // line of the scan in the log (for messages)
  // Per beam: the range as CARMEN stores it (parsed as double, kept as float).
  std::vector<float> range;

  ScanBatch() : beam_offset{0} {}
  size_t num_scans() const { return x.size(); }
  size_t num_beams() const { return range.size(); }
  // The accessors trust the arrays: call validate() first on a batch that
  // came from outside (bindings, callers' own arrays).
  int beams_in(size_t s) const { return static_cast<int>(beam_offset[s + 1] - beam_offset[s]); }
  const float *ranges_of(size_t s) const { return range.data() + beam_offset[s]; }

  // Throws vasco::Error(BadInput) naming the first scan whose arrays do not
  // agree: every per-scan array num_scans() long, beam_offset num_scans() + 1
  // long, starting at 0, never decreasing, ending at num_beams(), and every
  // scan's beam count an int.
  void validate() const;
  // validate(), then every pose (x, y, theta), first angle and angle step
  // finite: Error(BadInput) naming the first bad scan. What a mapping session
  // accepts.
  void validate_for_mapping() const;
  // Scan s's ranges after checking s and its offsets (for bindings that hand
  // out one scan): Error(Usage) for s out of range, else as validate().
  const float *checked_ranges_of(size_t s) const;

  void add_scan(double px, double py, double ptheta, double first, double step, const float *r,
                int n, long source_line);
  // Appends every scan of `other` (validated first).
  void append(const ScanBatch &other);
  // Takes every pose into another frame: the rigid transform (tx, ty, ta)
  // applied to it, x' = tx + cos(ta) x - sin(ta) y, y' = ty + sin(ta) x +
  // cos(ta) y, theta' = theta + ta (vasco::compose of pose_file.h). How a
  // session of several is put into the shared frame; the identity changes
  // no bit.
  void transform(double tx, double ty, double ta);
  // Keeps the first `scans` scans and their beams (scans <= num_scans());
  // never throws: how a failed append is undone.
  void truncate(size_t scans) noexcept;

  // Scans [first, first + count) (count < 0: to the end), clipped to the
  // batch: vasco_first_scan / vasco_num_scans. Validates the batch first. The
  // && form reuses this batch's arrays instead of copying them.
  ScanBatch select(long first, long count) const &;
  ScanBatch select(long first, long count) &&;
};

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

#endif  // VASCO_GPU_SCAN_BATCH_H
