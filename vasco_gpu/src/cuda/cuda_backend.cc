// Host side of the CUDA backend's one-shot interface (Backend::map/apply), on
// a mapping session's renderer; and whether a GPU is usable.
#include "vasco_gpu/cuda_backend.h"

#include <algorithm>
#include <cstddef>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <cmath>
#include <mutex>
#include <sstream>
#include <thread>
#include <vector>

#include "cuda_check.h"
#include "cuda_host_support.h"
#include "cuda_renderer.h"
#include "egrid_kernels.h"
#include "vasco_gpu/beam_placement.h"
#include "vasco_gpu/oracle.h"

namespace vasco {
namespace {

using Clock = std::chrono::steady_clock;
using cuda_host::check_fits;
using cuda_host::StageTimer;
using cuda::DeviceBuffer;
using cuda::Event;
using cuda::PinnedBuffer;
using cuda::Stream;

struct UsableState {
  std::once_flag once;
  bool usable = false;
  std::string why;
};

UsableState &usable_state() {
  static UsableState s;
  return s;
}

double seconds(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

class CudaBackend : public Backend {
 public:
  explicit CudaBackend(const BackendOptions &o) : options_(o) {
    VG_CUDA_CHECK(cudaSetDevice(o.cuda_device));
  }
  std::string name() const override { return options_.cuda_mode == CudaMode::Exact ? "cuda_exact" : "cuda_float"; }

  std::vector<float> map(const ScanBatch &batch, const MapperParams &params,
                         const GridGeometry &geo, MapStats *stats) override {
    // The grid on the device and its copy for the download, checked before
    // the host's copy is allocated.
    VG_CUDA_CHECK(cudaSetDevice(options_.cuda_device));
    check_fits(2 * geo.num_cells() * sizeof(float), "the evidence grid");
    std::vector<float> grid(geo.num_cells());
    run(batch, 0, batch.num_scans(), params, geo, grid.data(), true, stats);
    return grid;
  }

  // Uploads `cells`, applies the scans on the GPU, downloads the grid back.
  void apply(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
             const GridGeometry &geo, float *cells, MapStats *stats) override {
    run(batch, first, last, params, geo, cells, false, stats);
  }

 private:
  // fresh: the grid starts all unknown (nothing uploaded); else from `cells`.
  void run(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
           const GridGeometry &geo, float *cells, bool fresh, MapStats *stats) {
    VG_CUDA_CHECK(cudaSetDevice(options_.cuda_device));
    MapStats st;
    last = std::min(last, batch.num_scans());
    first = std::min(first, last);
    run_renderer(batch, first, last, params, geo, cells, fresh, &st);
    st.scans = last - first;
    if (stats != nullptr) *stats = st;
  }

  // Our kernels, through a mapping session's renderer: the grid goes up (when
  // continued) and comes back whole.
  void run_renderer(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
                    const GridGeometry &geo, float *cells, bool fresh, MapStats *st) {
    if (!renderer_) renderer_ = std::make_unique<CudaRenderer>(options_);
    renderer_->forget_scans();
    renderer_->reset(geo, params);
    if (!fresh) renderer_->upload_grid(cells);
    renderer_->apply(batch, first, last, st);
    const auto t_down = Clock::now();
    const std::vector<float> grid = renderer_->read(GridWindow{0, 0, geo.size_x, geo.size_y});
    std::copy(grid.begin(), grid.end(), cells);
    st->download_s = seconds(t_down);
  }

  BackendOptions options_;
  std::unique_ptr<CudaRenderer> renderer_;
};

}  // namespace

bool cuda_usable(int device, std::string *why) {
  UsableState &s = usable_state();
  std::call_once(s.once, [&] {
    int count = 0;
    cudaError_t err = cudaGetDeviceCount(&count);
    if (err != cudaSuccess) {
      s.why = std::string("no CUDA device (") + cudaGetErrorString(err) + ")";
      return;
    }
    if (device < 0 || device >= count) {
      s.why = "CUDA device " + std::to_string(device) + " does not exist (" + std::to_string(count) +
              " present)";
      return;
    }
    cudaDeviceProp prop;
    err = cudaGetDeviceProperties(&prop, device);
    if (err == cudaSuccess) err = cudaSetDevice(device);
    if (err == cudaSuccess) err = cudaFree(nullptr);  // creates the context
    if (err != cudaSuccess) {
      s.why = std::string("CUDA device ") + std::to_string(device) + " is not usable (" +
              cudaGetErrorString(err) + ")";
      return;
    }
    std::string image_why;
    if (!cuda::kernels_runnable_on_current_device(&image_why)) {
      s.why = std::string(prop.name) + " (compute capability " + std::to_string(prop.major) + "." +
              std::to_string(prop.minor) + ") cannot run this build's kernels (" + image_why +
              "): rebuild with its architecture in CMAKE_CUDA_ARCHITECTURES";
      return;
    }
    s.usable = true;
  });
  if (!s.usable && why != nullptr) *why = s.why;
  return s.usable;
}

std::string cuda_device_description(int device) {
  cudaDeviceProp prop;
  if (cudaGetDeviceProperties(&prop, device) != cudaSuccess) return "unknown device";
  std::ostringstream o;
  o << prop.name << ", " << prop.multiProcessorCount << " SMs, "
    << prop.totalGlobalMem / (1024.0 * 1024 * 1024) << " GiB";
  return o.str();
}

std::unique_ptr<Backend> make_cuda_backend(const BackendOptions &options) {
  std::string why;
  if (!cuda_usable(options.cuda_device, &why)) throw std::runtime_error("no usable GPU: " + why);
  return std::make_unique<CudaBackend>(options);
}

}  // namespace vasco
