// split_renderer.h — one render split across GPUs: the frame's columns cut
// in bands, one CUDA renderer (grid, stream, scratch) per band on its own
// device, every band given every scan. A cell's updates are its own band's
// alone, in the order the whole grid's render applies them (exact mode: one
// thread per cell, the beams in (scan, beam) order; float mode: integer sums,
// which no order changes), so the banded grid is the whole grid's, bit for
// bit. finish runs on each band's device and gathers only the finished map
// (split_renderer.cc says when it gathers the grid instead); read gathers
// the window's columns from the bands that hold them.
#ifndef VASCO_GPU_SRC_CUDA_SPLIT_RENDERER_H
#define VASCO_GPU_SRC_CUDA_SPLIT_RENDERER_H

#include <memory>
#include <string>
#include <vector>

#include "cuda_renderer.h"

namespace vasco {

// The bands a frame `size_x` columns wide is cut in for `parts` renderers:
// whole multiples of kBandAlign columns (the last takes the rest), as equal
// as that allows, none empty, so a frame narrower than parts * kBandAlign
// gets fewer bands. A frame wider than kMaxBandedSide is one band.
constexpr int kBandAlign = 32;  // tile borders of both modes (kTile, the y-major accumulator's 32)
std::vector<ColumnBand> split_columns(int size_x, int parts);

class SplitRenderer final : public Renderer {
 public:
  // One band per entry of `devices` (a device may repeat: bands that share
  // one GPU, which tests the split without several); `options` as for one
  // CUDA renderer (its cuda_device is not used).
  SplitRenderer(const BackendOptions &options, const std::vector<int> &devices);
  ~SplitRenderer() override;

  std::string name() const override { return parts_[0]->name(); }
  // A refused reset leaves the split without a grid (apply, finish and read
  // throw ErrorCode::State until a reset succeeds): the bands reset before
  // the refusal have dropped theirs. A Mapper renders again from its scans.
  void reset(const GridGeometry &geo, const MapperParams &params) override;
  // Every band applies the scans on a thread of its own; a failure in any
  // leaves the split's grid lost.
  void apply(const ScanBatch &scans, size_t first, size_t last, MapStats *stats) override;
  FinishedMap finish(int downsample, int border) override;
  std::vector<float> read(const GridWindow &window) override;
  void check_capacity(uint64_t beams) const override { parts_[0]->check_capacity(beams); }
  void forget_scans() override;
  RendererTraits traits() const override { return parts_[0]->traits(); }
  // The bands of the last reset, for reports.
  const std::vector<ColumnBand> &bands() const { return bands_; }
  const std::vector<int> &devices() const { return devices_; }

 private:
  void require_grid(const char *call) const;
  FinishedMap finish_on_host(int downsample, int border);
  // A window of the frame gathered from the bands it crosses (x-major).
  void gather(const GridWindow &window, std::vector<float> *out);

  std::vector<int> devices_;
  std::vector<std::unique_ptr<CudaRenderer>> parts_;
  std::vector<ColumnBand> bands_;  // bands_[i] is parts_[i]'s; fewer bands than parts for a narrow frame
  GridGeometry geo_;
  bool valid_ = false;
};

// The renderer of make_cuda_renderer for options.split_devices: a split of
// two or more bands, one device for each.
std::unique_ptr<Renderer> make_split_renderer(const BackendOptions &options);

}  // namespace vasco

#endif  // VASCO_GPU_SRC_CUDA_SPLIT_RENDERER_H
