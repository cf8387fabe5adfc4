// mapper.hpp — vasco::Mapper, the mapping session every interface uses
// (DESIGN §7): scans stored once, poses replaceable as a whole, an evidence
// grid kept between calls by a renderer of the chosen backend.
//
//   vasco::Mapper m(params, "cuda");       // or cpu_double, cpu_threads, cpu_float
//   m.insert(scans);                        // new scans continue the current grid
//   m.render(poses);                        // a loop closure: every pose moved, recomputed
//   vasco::FinishedMap map = m.finish();    // CARMEN's finish (downsample, crop)
//
// Exactness. With cpu_double, cpu_threads and CUDA exact mode the grid after
// inserting scans 0..k in any number of calls is bit-identical to mapping
// 0..k at once, and a render with poses P is bit-identical to a fresh map of a
// log carrying P (and so, for a CARMEN log, to CARMEN's map).
//
// The grid frame. By default the frame is the golden PROTOCOL's (DESIGN §3):
// centred on the first scan's pose, 2 * ceil((max |x - x0| + range_max + res)
// / res) + 2 cells wide (likewise in y), theta_offset = the first scan's
// heading — what log2map uses, so its maps stay CARMEN's. An insert whose
// scans lie farther out grows the frame to the PROTOCOL frame of all scans
// stored, and a render recomputes it from the new poses; either way the grid
// is then rendered afresh in the new frame, so a grown map equals a fresh
// render in the grown frame (growth costs one full render: give a fixed frame
// when scans arrive one by one far beyond the start). A fixed frame (given
// size, resolution and heading; centred on the first scan, as CARMEN's
// egrid.c) never changes: cells outside it are skipped, as CARMEN skips them.
#ifndef VASCO_GPU_MAPPER_HPP
#define VASCO_GPU_MAPPER_HPP

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "vasco_gpu/backend.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/renderer.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

class Mapper {
 public:
  // PROTOCOL frame. Throws std::invalid_argument for bad parameters or an
  // unknown backend, std::runtime_error when the backend cannot run here.
  Mapper(const MapperParams &params, const std::string &backend = "cpu_double",
         const BackendOptions &options = {});
  // Fixed frame: `frame.size_x`, `size_y`, `resolution` (must equal
  // params.resolution) and `theta_offset` are used; x0 and y0 are taken from
  // the first scan.
  Mapper(const MapperParams &params, const GridGeometry &frame, const std::string &backend,
         const BackendOptions &options = {});

  // Stores `scans` (ranges, beam geometry and poses) after those stored and
  // applies them to the current grid. Throws std::runtime_error when the
  // PROTOCOL frame would be too large, or the session would need more host
  // memory than BackendOptions::max_memory_bytes (nothing is stored then).
  void insert(const ScanBatch &scans);
  // New poses for every stored scan (poses.size() == num_scans()), and the
  // grid recomputed from scratch with them.
  void render(const std::vector<Pose> &poses);

  FinishedMap finish() const { return finish(static_cast<int>(params_.downsample), static_cast<int>(params_.border)); }
  FinishedMap finish(int downsample, int border) const;
  std::vector<float> read(const GridWindow &window) const;
  std::vector<float> read() const;  // the whole full-resolution grid

  size_t num_scans() const { return scans_.num_scans(); }
  const ScanBatch &scans() const { return scans_; }
  std::vector<Pose> poses() const;
  const GridGeometry &frame() const { return geo_; }
  const MapperParams &params() const { return params_; }
  std::string backend_name() const { return renderer_->name(); }
  // Counts and times of the last insert or render (a growth re-render included).
  const MapStats &last_stats() const { return stats_; }
  // Full renders since construction: one per render(), per growth, and the first insert.
  size_t renders() const { return renders_; }

 private:
  GridGeometry frame_for(const PoseExtent &extent, const ScanBatch &scans) const;
  void check_memory(const GridGeometry &geo, uint64_t beams) const;
  void rerender();

  MapperParams params_;
  BackendOptions options_;
  bool fixed_frame_ = false;
  GridGeometry geo_;
  ScanBatch scans_;
  PoseExtent extent_;  // of the stored scans' poses
  std::unique_ptr<Renderer> renderer_;
  MapStats stats_;
  size_t renders_ = 0;
};

}  // namespace vasco

#endif  // VASCO_GPU_MAPPER_HPP
