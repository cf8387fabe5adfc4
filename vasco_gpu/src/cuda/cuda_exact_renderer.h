// cuda_exact_renderer.h — CUDA exact mode, bit-identical to cpu_double: the
// beams are placed on the device with the oracle's end cells
// (device_placement.h; on the host with the oracle's code where the device
// cannot decide, or when VASCO_CUDA_HOST_PLACEMENT is set), listed per
// kTile x kTile tile in (scan, beam) order, and applied by a thread per
// cell with the oracle's double arithmetic. The ranges stay on the device
// between calls, as in float mode: a render sends a record per scan.
#ifndef VASCO_GPU_SRC_CUDA_EXACT_RENDERER_H
#define VASCO_GPU_SRC_CUDA_EXACT_RENDERER_H

#include "cuda_renderer.h"
#include "device_placement.h"
#include "vasco_gpu/internal/table_cache.h"

namespace vasco {

class CudaExactRenderer final : public CudaRenderer {
 public:
  CudaExactRenderer(const BackendOptions &options, cudaStream_t stream) : CudaRenderer(options, stream, true) {}
  std::string name() const override { return "cuda_exact"; }
  void forget_scans() override { placement_.ranges().forget(); }

 private:
  void reserve_grid(const GridGeometry &geo) override;
  void clear_grid() override;
  void apply_scans(const ScanBatch &scans, size_t first, size_t last, MapStats *st) override;
  cuda::GridCells cells() const override;
  double device_bytes_per_cell() const override;
  void ensure_tables();
  void apply_launch(const ScanBatch &scans, size_t first, size_t last, bool on_device, MapStats *st);
  bool place_on_device(const ScanBatch &scans, size_t first, size_t last, MapStats *st, uint64_t *pair_bound);
  uint64_t place_beams(const ScanBatch &scans, size_t first, size_t last, MapStats *st);
  size_t num_tiles() const { return tiles_of(grid_geo()); }
  static size_t tiles_of(const GridGeometry &geo);
  void reserve_scratch(uint64_t pair_bound, size_t tiles);
  void launch_tile_lists(const cuda::KernelModel<double> &m, uint64_t pair_bound, size_t tiles, cudaStream_t s,
                         cuda_host::StageTimer &timer);
  void launch_apply(uint64_t pair_bound, bool upload_beams, MapStats *st);
  void report_tile_lists(uint64_t pair_bound, size_t tiles);

  cuda::DeviceBuffer<float> grid_;  // probabilities, -1 unknown
  // The distance and odds-factor tables (they replace a sqrt and two
  // divisions per update), when small enough.
  bool use_tables_ = false;
  TableCache tables_key_;
  cuda::DeviceBuffer<double2> factors_;  // (free, occupied) odds factors
  cuda::DeviceBuffer<int> reach_;
  cuda_host::DevicePlacement placement_;
  // One launch's beams (placed on the device, or by place_beams into
  // staging_beams_) and the tile lists' scratch.
  uint64_t beams_ = 0;
  size_t scans_ = 0;
  cuda::DeviceBuffer<PlacedBeam> beams_dev_;
  cuda::DeviceBuffer<cuda::StartCell> starts_;
  cuda::DeviceBuffer<cuda::LineRec> lines_;
  cuda::DeviceBuffer<uint32_t> counts_, offsets_, tile_begin_, tile_end_, order_, order_keys_, order_keys_out_,
      order_ids_, pair_tile_, pair_beam_, sorted_tile_, sorted_beam_;
  cuda::DeviceBuffer<unsigned char> scan_tmp_, order_tmp_, sort_tmp_;
  cuda::DeviceBuffer<unsigned long long> updates_;
  cuda::DeviceBuffer<uint32_t> heavy_count_;  // how many tiles of order_ run heavy (exact_tile_order)
  // The heavy tiles' stream beside the renderer's, and its fork and join
  // (launch_exact_tiles); made on the first apply, on the renderer's device.
  std::unique_ptr<cuda::Stream> side_stream_;
  std::unique_ptr<cuda::Event> fork_, join_;
  cuda::PinnedBuffer<PlacedBeam> staging_beams_;
  cuda::PinnedBuffer<cuda::StartCell> staging_starts_;
  cuda::PinnedBuffer<unsigned long long> staging_counters_;
};

}  // namespace vasco

#endif  // VASCO_GPU_SRC_CUDA_EXACT_RENDERER_H
