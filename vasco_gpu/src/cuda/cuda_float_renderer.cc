#include "cuda_float_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "vasco_gpu/grid.h"
#include "vasco_gpu/internal/log_odds.h"
#include "vasco_gpu/internal/oracle.h"

namespace vasco {

using cuda_host::grow_to;

// The sums are what the grid needs (8 bytes a cell); the y-major accumulator
// (8 more) is taken only where it fits (across_scratch).
void CudaFloatRenderer::reserve_grid(const GridGeometry &geo) { grow_grid(sums_, geo); }

double CudaFloatRenderer::device_bytes_per_cell() const { return 2 * sizeof(unsigned long long); }

void CudaFloatRenderer::clear_grid() {
  cuda::launch_float_clear(sums_.get(), grid_geo().num_cells(), stream());
  beams_ = 0;
}

// Refuses a grid whose beams could carry a cell's fixed-point sum past
// kFixedLimit (egrid_kernels.h): a cell takes one update per beam at most,
// of at most `step` log-odds. vasco's defaults allow 2 x 10^7 beams, far
// beyond any log.
void CudaFloatRenderer::check_capacity(uint64_t beams) const {
  const MapperParams &p = params();
  const double step = std::max(std::fabs(logit(p.p_occ) - logit(p.p_prior)),
                               std::fabs(logit(p.p_emp) - logit(p.p_prior)));
  if (static_cast<double>(beams) * step > cuda::kFixedLimit)
    throw Error(ErrorCode::TooLarge, "cuda float mode: " + std::to_string(beams) +
                                         " beams could push a cell's log-odds past the fixed-point range (+-2^22); "
                                         "use the exact mode or a CPU backend for this log");
}

// The kernels' model of the grid: the band's cells, the scans placed in the
// whole frame.
cuda::KernelModel<float> CudaFloatRenderer::model() const {
  return kernel_model_of<float>(params(), grid_geo(), band_x0());
}

cuda::GridCells CudaFloatRenderer::cells() const {
  cuda::GridCells c;
  c.sums = sums_.get();
  c.logodds_prior = model().logodds_prior;
  return c;
}

// The increment tables for the current parameters (built when they change),
// or null when they would be too large.
const int2 *CudaFloatRenderer::tables() {
  const int T = params().table_size();
  if (T <= 0 || T > cuda::kMaxFloatTable || cuda_host::tables_disabled()) return nullptr;
  increments_key_.ensure(params(), [&] {
    grow_to(increments_, static_cast<size_t>(T) * static_cast<size_t>(T));
    cuda::launch_float_tables(model(), increments_.get(), stream());
  });
  return increments_.get();
}

// The y-major accumulator launch_float_map takes for the beams that step
// along x (coalesced adds; mapping_bench on the H200, map phase, median of
// 7, without -> with it: fr079 vasco_default_raw 1.60 -> 1.37 ms, paper 1.45
// -> 1.33; fr101 3.20 -> 2.63, 2.46 -> 2.02), for applies of many scans only: clearing it and adding it
// to the sums cost two passes over the grid, which a one-scan insert would
// not win back. It is scratch: where it does not fit in GPU memory the
// render goes without it (the same sums), never refused for it.
constexpr size_t kAcrossMinScans = 256;

// The transpose that adds it to the sums is launched with a block per 32 x 32
// cells and the y tiles in gridDim.y, which CUDA caps at 65535: a grid taller
// than that goes without (float_kernels.cu's add_across launch would fail).
constexpr int64_t kAcrossMaxSizeY = int64_t(65535) * 32;

unsigned long long *CudaFloatRenderer::across_scratch(size_t num_scans) {
  const size_t cells = grid_geo().num_cells();
  if (num_scans < kAcrossMinScans || cells == 0 || cuda_host::across_disabled()) return nullptr;
  if (grid_geo().size_y > kAcrossMaxSizeY) return nullptr;
  if (cells > across_.size()) {
    size_t free_b = 0, total_b = 0;
    VG_CUDA_CHECK(cudaMemGetInfo(&free_b, &total_b));
    const size_t bytes = (cuda_host::grown_size(across_.size(), cells) - across_.size()) * sizeof(unsigned long long);
    if (bytes + (size_t(256) << 20) > free_b) return nullptr;  // a margin for the rest of the session
    grow_to(across_, cells);
  }
  return across_.get();
}

// Checks, allocates and uploads first; the sums change only in launch_map.
void CudaFloatRenderer::apply_scans(const ScanBatch &scans, size_t first, size_t last, MapStats *st) {
  const auto t_prep = std::chrono::steady_clock::now();
  if (scans.beam_offset[last] > UINT32_MAX)
    throw Error(ErrorCode::TooLarge, "cuda float mode: more than 2^32 beams stored");
  const uint64_t beams = scans.beam_offset[last] - scans.beam_offset[first];
  check_capacity(beams_ + beams);
  const int2 *increments = tables();
  ranges_.upload(scans, last, stream());
  stage_scan_records(scans, first, last);
  grow_to(scan_records_, last - first);
  grow_to(counters_, 3);
  grow_to(staging_counters_, 3);
  unsigned long long *across = across_scratch(last - first);
  st->prep_s += seconds_since(t_prep);
  begin_update();
  launch_map(increments, across, last - first, st);
  ranges_.commit();
  beams_ += beams;
  end_update();
}

// The records of scans [first, last) into pinned staging, placed with scan
// 0 (or the given centre) fixing the start pose.
void CudaFloatRenderer::stage_scan_records(const ScanBatch &scans, size_t first, size_t last) {
  oracle::GridFrame frame = start_frame(geo(), scans);
  grow_to(staging_scans_, last - first);
  for (size_t s = first; s < last; ++s) {
    const oracle::ScanStart p = oracle::scan_start(frame, scans.x[s], scans.y[s], scans.theta[s]);
    cuda::FloatScan &f = staging_scans_[s - first];
    f.lx = static_cast<float>(p.lx);
    f.ly = static_cast<float>(p.ly);
    f.theta = static_cast<float>(p.theta);
    f.x1 = p.x1;
    f.y1 = p.y1;
    f.first = static_cast<float>(scans.first_angle[s]);
    f.step = static_cast<float>(scans.angle_step[s]);
    f.beam_begin = static_cast<uint32_t>(scans.beam_offset[s]);
    f.beam_count = scans.beams_in(s);
  }
}

void CudaFloatRenderer::launch_map(const int2 *increments, unsigned long long *across, size_t n, MapStats *st) {
  PhaseEvents &ev = events();
  cudaStream_t s = stream();
  ev.start.record(s);
  VG_CUDA_CHECK(cudaMemcpyAsync(scan_records_.get(), staging_scans_.get(), n * sizeof(cuda::FloatScan),
                                cudaMemcpyHostToDevice, s));
  VG_CUDA_CHECK(cudaMemsetAsync(counters_.get(), 0, 3 * sizeof(unsigned long long), s));
  ev.uploaded.record(s);
  cuda::launch_float_map(model(), increments, scan_records_.get(),
                         static_cast<int>(n), ranges_.get(), sums_.get(), across, counters_.get(), s);
  ev.mapped.record(s);
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_counters_.get(), counters_.get(), 3 * sizeof(unsigned long long),
                                cudaMemcpyDeviceToHost, s));
  VG_CUDA_CHECK(cudaStreamSynchronize(s));  // the call's result is complete
  st->beams_used += staging_counters_[0];
  st->beams_skipped += staging_counters_[1];
  st->cell_updates += staging_counters_[2];
  ev.add_times(st);
}

}  // namespace vasco
