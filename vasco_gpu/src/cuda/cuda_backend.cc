// Host side of the CUDA backend: prepares a scan batch, uploads it once, runs
// every scan on the GPU, downloads the grid once (the paper's working cycle).
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
#include "paper_kernels.h"
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

static_assert(sizeof(PlacedBeam) == sizeof(cuda::ExactBeam) &&
                  offsetof(PlacedBeam, x2) == offsetof(cuda::ExactBeam, x2) &&
                  offsetof(PlacedBeam, y2) == offsetof(cuda::ExactBeam, y2) &&
                  offsetof(PlacedBeam, scan) == offsetof(cuda::ExactBeam, scan) &&
                  offsetof(PlacedBeam, range) == offsetof(cuda::ExactBeam, range),
              "PlacedBeam is uploaded as cuda::ExactBeam");

class CudaBackend : public Backend {
 public:
  explicit CudaBackend(const BackendOptions &o) : options_(o) {
    VG_CUDA_CHECK(cudaSetDevice(o.cuda_device));
  }
  std::string name() const override {
    if (options_.cuda_mode == CudaMode::Exact) return "cuda_exact";
    switch (options_.cuda_kernel) {
      case CudaKernel::Ours: return "cuda_float";
      case CudaKernel::PaperPerScan: return "cuda_paper";
      case CudaKernel::PaperPerScanNoShared: return "cuda_paper_noshared";
      case CudaKernel::PaperPerScanNoConst: return "cuda_paper_noconst";
      case CudaKernel::PaperFused: return "cuda_paper_fused";
    }
    return "cuda_float";
  }

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
    if (options_.cuda_mode == CudaMode::Exact || options_.cuda_kernel == CudaKernel::Ours) {
      run_renderer(batch, first, last, params, geo, cells, fresh, &st);
    } else {
      if (!fresh) throw std::logic_error("the paper's kernels map whole batches only");
      map_paper(batch, params, geo, cells, &st);
    }
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

  // The paper's kernel and its ablation variants (benchmark baselines).
  void map_paper(const ScanBatch &batch, const MapperParams &params, const GridGeometry &geo,
                 float *host_grid, MapStats *st) {
    const auto t_prep = Clock::now();
    const std::vector<oracle::ScanStart> starts = place_scans(batch, geo);
    const size_t nscans = batch.num_scans();
    PinnedBuffer<cuda::FloatScan> h_scans(std::max<size_t>(nscans, 1));
    for (size_t s = 0; s < nscans; ++s) {
      cuda::FloatScan f;
      f.lx = static_cast<float>(starts[s].lx);
      f.ly = static_cast<float>(starts[s].ly);
      f.theta = static_cast<float>(starts[s].theta);
      f.x1 = starts[s].x1;
      f.y1 = starts[s].y1;
      f.first = static_cast<float>(batch.first_angle[s]);
      f.step = static_cast<float>(batch.angle_step[s]);
      f.beam_begin = static_cast<uint32_t>(batch.beam_offset[s]);
      f.beam_count = batch.beams_in(s);
      h_scans[s] = f;
    }
    const cuda::FloatModel m = float_model_of(params, geo);
    st->prep_s = seconds(t_prep);

    const size_t cells = geo.num_cells(), nbeams = batch.num_beams();
    if (nbeams > UINT32_MAX) throw std::runtime_error("the paper's kernels: more than 2^32 beams");
    check_fits(cells * (sizeof(float) + 1) + nbeams * sizeof(float) + nscans * sizeof(cuda::FloatScan),
               "float mode (grid and beams)");
    Stream stream;
    Event e0, e_up, e_map, e_down;
    DeviceBuffer<cuda::FloatScan> d_scans(nscans);
    DeviceBuffer<float> d_ranges(nbeams), d_grid(cells);
    DeviceBuffer<uint8_t> d_touched(cells);
    DeviceBuffer<unsigned long long> d_counters(3);
    DeviceBuffer<cuda::FloatModel> d_model(1);

    e0.record(stream.get());
    if (nscans)
      VG_CUDA_CHECK(cudaMemcpyAsync(d_scans.get(), h_scans.get(), nscans * sizeof(cuda::FloatScan),
                                    cudaMemcpyHostToDevice, stream.get()));
    if (nbeams)
      VG_CUDA_CHECK(cudaMemcpyAsync(d_ranges.get(), batch.range.data(), nbeams * sizeof(float),
                                    cudaMemcpyHostToDevice, stream.get()));
    e_up.record(stream.get());
    StageTimer timer(stream.get());
    timer.mark("start");
    VG_CUDA_CHECK(cudaMemsetAsync(d_grid.get(), 0, cells * sizeof(float), stream.get()));
    VG_CUDA_CHECK(cudaMemsetAsync(d_touched.get(), 0, cells, stream.get()));
    timer.mark("clear");
    VG_CUDA_CHECK(cudaMemsetAsync(d_counters.get(), 0, 3 * sizeof(unsigned long long), stream.get()));
    cuda::PaperVariant v = cuda::PaperVariant::PerScan;
    if (options_.cuda_kernel == CudaKernel::PaperPerScanNoShared) v = cuda::PaperVariant::PerScanNoShared;
    if (options_.cuda_kernel == CudaKernel::PaperPerScanNoConst) v = cuda::PaperVariant::PerScanNoConst;
    if (options_.cuda_kernel == CudaKernel::PaperFused) v = cuda::PaperVariant::Fused;
    VG_CUDA_CHECK(cudaMemcpyAsync(d_model.get(), &m, sizeof m, cudaMemcpyHostToDevice, stream.get()));
    cuda::run_paper_variant(v, m, d_model.get(), h_scans.get(), d_scans.get(), static_cast<int>(nscans),
                            d_ranges.get(), d_grid.get(), d_touched.get(), stream.get());
    timer.mark("map");
    cuda::launch_float_finalize(m, d_grid.get(), d_touched.get(), cells, stream.get());
    timer.mark("finalize");
    e_map.record(stream.get());
    VG_CUDA_CHECK(cudaMemcpyAsync(host_grid, d_grid.get(), cells * sizeof(float),
                                  cudaMemcpyDeviceToHost, stream.get()));
    e_down.record(stream.get());
    stream.synchronize();
    timer.report();
    st->upload_s = e_up.since(e0) / 1e3;
    st->map_s = e_map.since(e_up) / 1e3;
    st->download_s = e_down.since(e_map) / 1e3;
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
