// scan_batch.h — the laser scans of a log, as a structure of arrays: what
// every backend consumes (and what the CUDA backend uploads once). Reading
// them from a CARMEN log is the pipeline's (vasco_gpu/pipeline/log_scans.h).
#ifndef VASCO_GPU_SCAN_BATCH_H
#define VASCO_GPU_SCAN_BATCH_H

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vasco {

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
  // cos(ta) y, theta' = theta + ta (vasco::compose of internal/se2.h). How a
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

}  // namespace vasco

#endif  // VASCO_GPU_SCAN_BATCH_H
