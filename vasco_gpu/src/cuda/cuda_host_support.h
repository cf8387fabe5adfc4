// cuda_host_support.h — host-side helpers shared by the CUDA renderers:
// the GPU-memory check, buffer growth, the per-stage profile, the kernels'
// model of a grid.
#ifndef VASCO_GPU_SRC_CUDA_HOST_SUPPORT_H
#define VASCO_GPU_SRC_CUDA_HOST_SUPPORT_H

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iomanip>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cuda_check.h"
#include "egrid_kernels.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/internal/sensor_params.h"
#include "vasco_gpu/internal/timing.h"

namespace vasco {
namespace cuda_host {

using cuda::Event;

inline std::string mib(size_t bytes) {
  std::ostringstream s;
  s << (bytes + (1 << 20) - 1) / (1 << 20) << " MiB";
  return s.str();
}

// Refuses, with a clear message, a job whose device memory would not fit.
inline void check_fits(size_t bytes, const char *what) {
  size_t free_b = 0, total_b = 0;
  VG_CUDA_CHECK(cudaMemGetInfo(&free_b, &total_b));
  // Keep a margin for CUB scratch rounding and the context.
  if (bytes + (size_t(64) << 20) > free_b)
    throw Error(ErrorCode::OutOfMemory, std::string("the map does not fit in GPU memory: ") + what + " needs " +
                                            mib(bytes) + ", " + mib(free_b) + " free of " + mib(total_b) +
                                            " (use a coarser vasco_resolution or a CPU backend)");
}

// "the evidence grid of 20000 x 20000 cells (8 bytes a cell)", for check_fits.
inline std::string grid_description(const GridGeometry &geo, double bytes_per_cell) {
  std::ostringstream s;
  s << "the evidence grid of " << geo.size_x << " x " << geo.size_y << " cells (" << std::setprecision(3)
    << bytes_per_cell << " bytes a cell)";
  return s.str();
}

// Whether the switch `name` is set: present, not empty and not "0".
inline bool env_flag(const char *name) {
  const char *v = std::getenv(name);
  return v != nullptr && *v != '\0' && std::string(v) != "0";
}

// VASCO_CUDA_NO_TABLES=1 computes every update in full, as grids too large
// for the tables are: the tests compare both ways bit for bit.
inline bool tables_disabled() { return env_flag("VASCO_CUDA_NO_TABLES"); }

// VASCO_CUDA_NO_ACROSS=1 maps float mode without its y-major accumulator
// (cuda_float_renderer.cc), as a grid too large for it is: for the tests
// and benchmarks that compare both ways.
inline bool across_disabled() { return env_flag("VASCO_CUDA_NO_ACROSS"); }

// VASCO_CUDA_HOST_PLACEMENT=1 places exact mode's beams on the host, as
// before the device placement (device_placement.h): for the benchmarks that
// compare the two.
inline bool host_placement_forced() { return env_flag("VASCO_CUDA_HOST_PLACEMENT"); }

// With VASCO_CUDA_PROFILE set, prints the time of each GPU stage to stderr
// (events between stages; for tuning, not for the benchmark table).
class StageTimer {
 public:
  explicit StageTimer(cudaStream_t s) : stream_(s), on_(std::getenv("VASCO_CUDA_PROFILE") != nullptr) {}
  void mark(const char *name) {
    if (!on_) return;
    events_.emplace_back(std::make_unique<Event>(), name);
    events_.back().first->record(stream_);
  }
  void report() {
    if (!on_ || events_.size() < 2) return;
    VG_CUDA_CHECK(cudaStreamSynchronize(stream_));
    for (size_t i = 1; i < events_.size(); ++i)
      std::fprintf(stderr, "  [cuda] %-14s %8.3f ms\n", events_[i].second,
                   events_[i].first->since(*events_[i - 1].first));
  }

 private:
  cudaStream_t stream_;
  bool on_;
  std::vector<std::pair<std::unique_ptr<Event>, const char *>> events_;
};


// The size a buffer of `have` elements grows to for `n` (half as much again,
// so that a session appending scans reallocates rarely).
inline size_t grown_size(size_t have, size_t n) { return n > have ? std::max(n, have + have / 2) : have; }

// The device memory grow_to(b, n) would take beyond what b holds (it frees
// the old buffer before allocating the grown one); 0 when b holds n already.
template <class T>
size_t growth_bytes(const cuda::DeviceBuffer<T> &b, size_t n) {
  return n > b.size() ? (grown_size(b.size(), n) - b.size()) * sizeof(T) : 0;
}

// Grows a buffer to at least n elements; its contents are dropped.
template <class Buffer>
void grow_to(Buffer &b, size_t n) {
  if (n > b.size()) b.resize(grown_size(b.size(), n));
}

// grow_to() of a device buffer, refused first (check_fits) when the growth
// would not fit in GPU memory: a refusal leaves the buffer as it was.
template <class T>
void grow_to_checked(cuda::DeviceBuffer<T> &b, size_t n, const char *what) {
  if (n <= b.size()) return;
  check_fits((grown_size(b.size(), n) - b.size()) * sizeof(T), what);
  grow_to(b, n);
}

}  // namespace cuda_host

// The kernels' model for a grid in their mode's precision (double: exact
// mode, float: float mode), with both modes' derived constants.
template <class Real>
cuda::KernelModel<Real> kernel_model_of(const MapperParams &p, const GridGeometry &geo, int x_begin = 0) {
  cuda::KernelModel<Real> m{};
  m.x_begin = x_begin;
  m.sensor = sensor_model_of<Real>(p);
  m.resolution = static_cast<Real>(p.resolution);
  m.wall = static_cast<Real>(p.wall_size);
  m.table_size = p.table_size();
  m.size_x = geo.size_x;
  m.size_y = geo.size_y;
  const int64_t t = std::max(m.table_size, 0);
  m.n_sure = m.table_size <= cuda::kMaxExactTable
                 ? static_cast<int>(egrid::first_square_not_below(p.range_sure, p.resolution, 2 * t * t))
                 : 0;
  m.factor_free_near = egrid::odds_factor(p.p_prior, p.p_emp);  // sensor_model's p below max_sure_range
  m.factor_occ_near = egrid::odds_factor(p.p_prior, p.p_occ);
  m.logodds_prior = static_cast<Real>(std::log(p.p_prior / (1 - p.p_prior)));
  return m;
}

}  // namespace vasco

#endif  // VASCO_GPU_SRC_CUDA_HOST_SUPPORT_H
