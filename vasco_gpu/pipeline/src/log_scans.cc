// The laser scans of a CARMEN log; see log_scans.h.
#include "vasco_gpu/pipeline/log_scans.h"

#include <climits>
#include <iterator>
#include <utility>

#include "vasco_gpu/params.h"

namespace vasco {

namespace {
// The scan message types, in the order messages name them.
constexpr carmen::MessageType kScanMessages[] = {carmen::MessageType::FLASER, carmen::MessageType::ROBOTLASER1};
}  // namespace

bool is_scan_message(carmen::MessageType type) {
  for (carmen::MessageType t : kScanMessages)
    if (t == type) return true;
  return false;
}

uint32_t scan_message_bits() {
  uint32_t bits = 0;
  for (carmen::MessageType t : kScanMessages) bits |= carmen::message_type_bit(t);
  return bits;
}

std::string scan_message_names(const char *joiner) {
  std::string names;
  for (carmen::MessageType t : kScanMessages) {
    if (!names.empty()) names += t == kScanMessages[std::size(kScanMessages) - 1] ? joiner : ", ";
    names += carmen::message_type_name(t);
  }
  return names;
}

ScanBatch load_scans(const std::string &log_path, const MapperParams &params,
                     const carmen::LogReaderOptions &options, LogLoadStats *stats,
                     const std::function<void(uint64_t, uint64_t)> &progress) {
  carmen::LogReader reader(log_path, options);
  carmen::LogMessage msg;
  ScanBatch batch;
  LogLoadStats st;
  const long first = params.first_scan;
  // exclusive; first + num_scans may not fit a long (vasco_first_scan near LONG_MAX)
  const long last = params.num_scans < 0 || params.num_scans > LONG_MAX - first ? -1 : first + params.num_scans;
  long since_progress = 0;
  while (reader.next(msg)) {
    if (progress && ++since_progress >= 2048) {
      since_progress = 0;
      progress(reader.compressed_bytes_read(), reader.file_size());
    }
    if (is_scan_message(msg.type)) {
      const long index = st.laser_messages++;
      if (index < first || (last >= 0 && index >= last)) continue;
      const carmen::LaserMessage &l = msg.laser;
      batch.add_scan(l.laser_pose.x, l.laser_pose.y, l.laser_pose.theta, l.config.start_angle,
                     l.config.angular_resolution, l.range.data(), static_cast<int>(l.range.size()), msg.line);
      st.stamps.push_back(l.timestamp);
      st.robot_poses.push_back(l.robot_pose);
      st.robot_pose_known.push_back(msg.type == carmen::MessageType::ROBOTLASER1);
    } else if (msg.type == carmen::MessageType::PARAM) {
      st.params.emplace_back(msg.param.name, msg.param.value);
      st.param_lines.push_back(msg.line);
    }
  }
  if (progress) progress(reader.file_size(), reader.file_size());
  st.scans_used = static_cast<long>(batch.num_scans());
  st.log = reader.stats();
  if (stats != nullptr) *stats = std::move(st);
  return batch;
}

}  // namespace vasco
