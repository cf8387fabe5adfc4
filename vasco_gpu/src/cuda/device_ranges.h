// device_ranges.h — CUDA float mode's device copy of a session's ranges,
// append-only: scans already there are not sent again (a render sends
// none). New ranges count as stored only once the apply that sent them
// succeeded (commit), so that after a failed one a session that dropped its
// scans and stored others sends those instead of trusting stale ranges.
#ifndef VASCO_GPU_SRC_CUDA_DEVICE_RANGES_H
#define VASCO_GPU_SRC_CUDA_DEVICE_RANGES_H

#include <cstdint>

#include "cuda_check.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {
namespace cuda_host {

class DeviceRanges {
 public:
  // Sends the ranges of beams [stored, scans.beam_offset[last]) on `stream`,
  // growing the buffer first (refused by check_fits when it would not fit:
  // nothing changes then). The stream must be idle (staging is reused).
  void upload(const ScanBatch &scans, size_t last, cudaStream_t stream);
  // The ranges sent since the last commit are those of the session's scans.
  void commit() { stored_ = sent_; }
  // The session's scans are others now: none of the ranges here is theirs.
  void forget() { stored_ = sent_ = 0; }
  const float *get() const { return ranges_.get(); }

 private:
  void grow(uint64_t need, cudaStream_t stream);

  cuda::DeviceBuffer<float> ranges_;
  cuda::PinnedBuffer<float> staging_;
  uint64_t stored_ = 0;  // beams whose ranges are the session's
  uint64_t sent_ = 0;    // beams whose ranges are on the device
};

}  // namespace cuda_host
}  // namespace vasco

#endif  // VASCO_GPU_SRC_CUDA_DEVICE_RANGES_H
