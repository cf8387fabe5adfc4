#include "device_ranges.h"

#include <algorithm>
#include <cstring>

#include "cuda_host_support.h"

namespace vasco {
namespace cuda_host {

void DeviceRanges::upload(const ScanBatch &scans, size_t last, cudaStream_t stream) {
  const uint64_t need = scans.beam_offset[last];
  sent_ = stored_;  // what an uncommitted upload sent may not be these scans'
  if (need <= stored_) return;
  if (need > ranges_.size()) grow(need, stream);
  const size_t n = need - stored_;
  grow_to(staging_, n);
  std::memcpy(staging_.get(), scans.range.data() + stored_, n * sizeof(float));
  VG_CUDA_CHECK(cudaMemcpyAsync(ranges_.get() + stored_, staging_.get(), n * sizeof(float),
                                cudaMemcpyHostToDevice, stream));
  sent_ = need;
}

// A larger buffer beside the old one (so both must fit), the stored ranges
// copied over: a refusal or a failed allocation keeps the old buffer.
void DeviceRanges::grow(uint64_t need, cudaStream_t stream) {
  const size_t grown = grown_size(ranges_.size(), need);
  check_fits(grown * sizeof(float), "the scans' ranges");
  cuda::DeviceBuffer<float> bigger(grown);
  if (stored_)
    VG_CUDA_CHECK(cudaMemcpyAsync(bigger.get(), ranges_.get(), stored_ * sizeof(float), cudaMemcpyDeviceToDevice,
                                  stream));
  VG_CUDA_CHECK(cudaStreamSynchronize(stream));  // the old buffer is freed next
  ranges_ = std::move(bigger);
}

}  // namespace cuda_host
}  // namespace vasco
