// cuda_renderer.h — the CUDA renderer of a mapping session (private to the
// library: make_cuda_renderer in cuda_backend.h creates one).
#ifndef VASCO_GPU_SRC_CUDA_RENDERER_H
#define VASCO_GPU_SRC_CUDA_RENDERER_H

#include <memory>
#include <optional>
#include <string>

#include "cuda_check.h"
#include "egrid_kernels.h"
#include "vasco_gpu/cuda_backend.h"
#include "vasco_gpu/mapper.hpp"

namespace vasco {

class CudaRenderer : public Renderer {
 public:
  explicit CudaRenderer(const BackendOptions &options);
  ~CudaRenderer() override;
  std::string name() const override;
  RendererTraits traits() const override { return {exact(), true}; }
  void reset(const GridGeometry &geo, const MapperParams &params) override;
  void apply(const ScanBatch &scans, size_t first, size_t last, MapStats *stats) override;
  FinishedMap finish(int downsample, int border) override;
  std::vector<float> read(const GridWindow &window) override;

  // For the one-shot backend: a grid of probabilities to continue (after
  // reset), and a batch that is not the one whose ranges are on the device.
  void upload_grid(const float *probabilities);
  void forget_scans();

 private:
  bool exact() const { return options_.cuda_mode == CudaMode::Exact; }
  cuda::GridCells cells() const;
  void check_capacity(uint64_t beams) const override;
  void build_tables();
  const int2 *float_tables();
  uint64_t exact_beams_per_launch() const;
  void upload_ranges(const ScanBatch &scans, size_t last);
  void apply_float(const ScanBatch &scans, size_t first, size_t last, MapStats *st);
  void apply_exact(const ScanBatch &scans, size_t first, size_t last, MapStats *st);
  uint64_t place_exact_beams(const ScanBatch &scans, size_t first, size_t last, MapStats *st);
  void reserve_exact_scratch(uint64_t pair_bound, size_t tiles);
  void launch_exact_apply(uint64_t pair_bound, MapStats *st);
  void report_tile_lists(uint64_t pair_bound, size_t tiles);

  BackendOptions options_;
  std::unique_ptr<cuda::Stream> stream_;
  std::unique_ptr<cuda::Event> e_start_, e_uploaded_, e_mapped_;  // phase times of an apply
  GridGeometry geo_;
  MapperParams params_;
  cuda::DeviceBuffer<float> grid_;                // exact mode: probabilities
  cuda::DeviceBuffer<unsigned long long> sums_;  // float mode: fixed-point log-odds sums
  // Float mode: beams applied since the reset, and the |log-odds| a cell
  // could hold before them (uploaded probabilities saturate at 2^20).
  uint64_t float_beams_ = 0;
  double fixed_base_ = 0;
  // Float mode's increment tables (launch_float_tables), when small enough.
  cuda::DeviceBuffer<int2> increments_;
  std::optional<MapperParams::TableKey> float_tables_key_;  // what they were built for
  // Float mode: the stored scans' ranges (append-only) and per-scan records.
  cuda::DeviceBuffer<float> ranges_;
  uint64_t stored_beams_ = 0;
  cuda::DeviceBuffer<cuda::FloatScan> scan_records_;
  cuda::DeviceBuffer<unsigned long long> counters_;
  // Exact mode: tables, beams and the tile lists' scratch.
  bool use_tables_ = false;
  std::optional<MapperParams::TableKey> tables_key_;  // what they were built for
  cuda::DeviceBuffer<double2> factors_;  // (free, occupied) odds factors
  cuda::DeviceBuffer<int> reach_;
  uint64_t exact_beams_ = 0;  // placed by place_exact_beams, in staging_beams_
  size_t exact_scans_ = 0;
  cuda::DeviceBuffer<PlacedBeam> beams_;
  cuda::DeviceBuffer<cuda::StartCell> starts_;
  cuda::DeviceBuffer<cuda::LineRec> lines_;
  cuda::DeviceBuffer<uint32_t> counts_, offsets_, tile_begin_, tile_end_, order_, order_keys_, order_keys_out_,
      order_ids_, pair_tile_, pair_beam_, sorted_tile_, sorted_beam_;
  cuda::DeviceBuffer<unsigned char> scan_tmp_, order_tmp_, sort_tmp_;
  cuda::DeviceBuffer<unsigned long long> updates_;
  // Finish and read.
  cuda::DeviceBuffer<float> blocks_, finished_, window_;
  cuda::DeviceBuffer<int> bbox_;
  // Pinned staging, both ways.
  cuda::PinnedBuffer<float> staging_ranges_, staging_out_;
  cuda::PinnedBuffer<cuda::FloatScan> staging_scans_;
  cuda::PinnedBuffer<PlacedBeam> staging_beams_;
  cuda::PinnedBuffer<cuda::StartCell> staging_starts_;
  cuda::PinnedBuffer<unsigned long long> staging_counters_;
  cuda::PinnedBuffer<uint32_t> staging_pairs_;
  cuda::PinnedBuffer<int> staging_bbox_;
};

}  // namespace vasco

#endif  // VASCO_GPU_SRC_CUDA_RENDERER_H
