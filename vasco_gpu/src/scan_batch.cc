#include "vasco_gpu/scan_batch.h"

#include <algorithm>
#include <climits>

#include "vasco_gpu/params.h"

namespace vasco {

void ScanBatch::add_scan(double px, double py, double ptheta, double first, double step,
                         const float *r, int n, long source_line) {
  x.push_back(px);
  y.push_back(py);
  theta.push_back(ptheta);
  first_angle.push_back(first);
  angle_step.push_back(step);
  line.push_back(source_line);
  range.insert(range.end(), r, r + n);
  beam_offset.push_back(range.size());
}

ScanBatch ScanBatch::select(long first, long count) const {
  ScanBatch out;
  const long n = static_cast<long>(num_scans());
  const long begin = std::min(std::max(first, 0L), n);
  const long end = (count < 0 || count > n - begin) ? n : begin + count;
  for (long s = begin; s < end; ++s)
    out.add_scan(x[s], y[s], theta[s], first_angle[s], angle_step[s], ranges_of(s), beams_in(s), line[s]);
  return out;
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
    switch (msg.type) {
      case carmen::MessageType::FLASER:
      case carmen::MessageType::ROBOTLASER1: {
        const long index = st.laser_messages++;
        if (index < first || (last >= 0 && index >= last)) break;
        const carmen::LaserMessage &l = msg.laser;
        batch.add_scan(l.laser_pose.x, l.laser_pose.y, l.laser_pose.theta, l.config.start_angle,
                       l.config.angular_resolution, l.range.data(), static_cast<int>(l.range.size()),
                       msg.line);
        break;
      }
      case carmen::MessageType::PARAM:
        st.params.emplace_back(msg.param.name, msg.param.value);
        st.param_lines.push_back(msg.line);
        break;
      default:
        break;
    }
  }
  if (progress) progress(reader.file_size(), reader.file_size());
  st.scans_used = static_cast<long>(batch.num_scans());
  st.log = reader.stats();
  if (stats != nullptr) *stats = std::move(st);
  return batch;
}

}  // namespace vasco
