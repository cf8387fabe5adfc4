// cuda_float_renderer.h — CUDA float mode: every scan of an apply in one
// launch, a warp per beam, a thread per cell, log-odds summed in 64-bit fixed
// point with integer atomics (egrid_kernels.h). The ranges stay on the
// device between calls: an insert sends its scans' ranges once and a
// 32-byte record per scan, a render the records only.
#ifndef VASCO_GPU_SRC_CUDA_FLOAT_RENDERER_H
#define VASCO_GPU_SRC_CUDA_FLOAT_RENDERER_H

#include "cuda_renderer.h"
#include "device_ranges.h"
#include "vasco_gpu/internal/table_cache.h"

namespace vasco {

class CudaFloatRenderer final : public CudaRenderer {
 public:
  CudaFloatRenderer(const BackendOptions &options, cudaStream_t stream) : CudaRenderer(options, stream, false) {}
  std::string name() const override { return "cuda_float"; }
  void check_capacity(uint64_t beams) const override;
  void forget_scans() override { ranges_.forget(); }

 private:
  void reserve_grid(const GridGeometry &geo) override;
  void clear_grid() override;
  void apply_scans(const ScanBatch &scans, size_t first, size_t last, MapStats *st) override;
  cuda::GridCells cells() const override;
  cuda::KernelModel<float> model() const;
  double device_bytes_per_cell() const override;
  const int2 *tables();
  void stage_scan_records(const ScanBatch &scans, size_t first, size_t last);
  void launch_map(const int2 *tables, unsigned long long *across, size_t num_scans, MapStats *st);
  unsigned long long *across_scratch(size_t num_scans);

  cuda::DeviceBuffer<unsigned long long> sums_;  // fixed-point log-odds sums
  cuda::DeviceBuffer<unsigned long long> across_;  // a render's y-major accumulator (launch_float_map)
  uint64_t beams_ = 0;                            // applied since the reset
  cuda::DeviceBuffer<int2> increments_;           // launch_float_tables', when small enough
  TableCache increments_key_;
  cuda_host::DeviceRanges ranges_;
  cuda::DeviceBuffer<cuda::FloatScan> scan_records_;
  cuda::DeviceBuffer<unsigned long long> counters_;
  cuda::PinnedBuffer<cuda::FloatScan> staging_scans_;
  cuda::PinnedBuffer<unsigned long long> staging_counters_;
};

}  // namespace vasco

#endif  // VASCO_GPU_SRC_CUDA_FLOAT_RENDERER_H
