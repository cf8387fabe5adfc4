// device_placement.h — CUDA exact mode's beam placement on the GPU: the end
// cells the host's oracle code gives (beam_placement.h), bit for bit, from
// the device's copy of the ranges and a 48-byte record per scan, so that a
// render sends the poses only. The few beams whose end cell the device
// cannot decide (egrid_kernels.h, ExactScan) are placed by the host with
// the oracle's code and patched in.
#ifndef VASCO_GPU_SRC_CUDA_DEVICE_PLACEMENT_H
#define VASCO_GPU_SRC_CUDA_DEVICE_PLACEMENT_H

#include <cstdint>
#include <vector>

#include "cuda_host_support.h"
#include "device_ranges.h"
#include "vasco_gpu/internal/oracle.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {
namespace cuda_host {

class DevicePlacement {
 public:
  struct Placed {
    bool done = false;  // false: more beams were unsure than the list holds; nothing usable was placed
    uint64_t beams = 0, skipped = 0;
    uint64_t pair_bound = 0;  // exact_tile_bound.h's sum over the placed beams
    uint64_t unsure = 0;      // beams the host placed
  };

  // The session's ranges on the device (DeviceRanges: upload, commit, forget).
  DeviceRanges &ranges() { return ranges_; }

  // Places scans [first, last) of `scans` in the frame `geo` (scan 0 fixes
  // the start pose) into beams[0 .. beams) and their start cells into
  // starts[0 .. last - first), growing both; their ranges must have been
  // uploaded. Waits for the device (the count sizes what follows).
  Placed place(const ScanBatch &scans, size_t first, size_t last, const GridGeometry &geo,
               const MapperParams &params, cuda::DeviceBuffer<PlacedBeam> &beams,
               cuda::DeviceBuffer<cuda::StartCell> &starts, cudaStream_t stream);

 private:
  void stage_scans(const ScanBatch &scans, size_t first, size_t last, const GridGeometry &geo);
  void reserve_scratch(size_t num_beams, size_t num_scans);
  void fix_unsure(size_t n, const cuda::PlacementModel &m, PlacedBeam *device_beams, cudaStream_t stream);

  DeviceRanges ranges_;
  std::vector<oracle::ScanStart> starts_host_;
  cuda::PinnedBuffer<cuda::ExactScan> staging_scans_;
  cuda::PinnedBuffer<cuda::StartCell> staging_starts_;
  cuda::PinnedBuffer<unsigned long long> staging_counters_;  // pair bound, unsure
  cuda::PinnedBuffer<uint32_t> staging_used_;
  cuda::PinnedBuffer<cuda::UnsureBeam> staging_unsure_;
  cuda::PinnedBuffer<cuda::BeamFix> staging_fixes_;
  cuda::DeviceBuffer<cuda::ExactScan> scans_dev_;
  cuda::DeviceBuffer<uint32_t> used_, slots_;
  cuda::DeviceBuffer<unsigned char> scan_tmp_;
  cuda::DeviceBuffer<cuda::UnsureBeam> unsure_;
  cuda::DeviceBuffer<cuda::BeamFix> fixes_;
  cuda::DeviceBuffer<unsigned long long> counters_;
};

}  // namespace cuda_host
}  // namespace vasco

#endif  // VASCO_GPU_SRC_CUDA_DEVICE_PLACEMENT_H
