#include "vasco_gpu/backend.h"

#include <algorithm>

#include <stdexcept>

#include "vasco_gpu/cpu_threads_backend.h"
#include "vasco_gpu/renderer.h"

#if defined(VASCO_HAVE_CUDA)
#include "vasco_gpu/cuda_backend.h"
#endif

namespace vasco {
namespace {

// A renderer whose grid lives in host memory and whose backend applies
// scans to it in place: every CPU backend (CUDA sessions have their own
// renderer, cuda_renderer.cc).
class HostRenderer : public Renderer {
 public:
  explicit HostRenderer(std::unique_ptr<Backend> backend) : backend_(std::move(backend)) {}
  std::string name() const override { return backend_->name(); }
  RendererTraits traits() const override { return {backend_->name() != "cpu_float", false}; }

  void reset(const GridGeometry &geo, const MapperParams &params) override {
    geo_ = geo;
    params_ = params;
    cells_.assign(geo.num_cells(), -1.0f);  // keeps the allocation when the size does not grow
  }

  void apply(const ScanBatch &scans, size_t first, size_t last, MapStats *stats) override {
    backend_->apply(scans, first, last, params_, geo_, cells_.data(), stats);
  }

  FinishedMap finish(int downsample, int border) override {
    return finish_grid(cells_.data(), geo_.size_x, geo_.size_y, geo_.resolution, downsample, border);
  }

  std::vector<float> read(const GridWindow &w) override {
    std::vector<float> out(static_cast<size_t>(w.width) * static_cast<size_t>(w.height));
    for (int x = 0; x < w.width; ++x) {
      const float *col = cells_.data() + static_cast<size_t>(w.x0 + x) * geo_.size_y + w.y0;
      std::copy(col, col + w.height, out.begin() + static_cast<size_t>(x) * w.height);
    }
    return out;
  }

 private:
  std::unique_ptr<Backend> backend_;
  GridGeometry geo_;
  MapperParams params_;
  std::vector<float> cells_;
};

}  // namespace


std::vector<std::string> compiled_backends() {
  std::vector<std::string> names = {"cpu_double", "cpu_threads", "cpu_float"};
#if defined(VASCO_HAVE_CUDA)
  names.push_back("cuda");
#endif
  return names;
}

std::unique_ptr<Backend> make_backend(const std::string &name, const BackendOptions &options) {
  if (name == "cpu_double") return make_cpu_double_backend();
  if (name == "cpu_threads") return make_cpu_threads_backend(options.threads);
  if (name == "cpu_float") return make_cpu_float_backend();
  if (name == "cuda" || name == "auto") {
#if defined(VASCO_HAVE_CUDA)
    std::string why;
    if (cuda_usable(options.cuda_device, &why)) return make_cuda_backend(options);
    if (name == "cuda") throw std::runtime_error("--backend cuda: no usable GPU: " + why);
#else
    if (name == "cuda")
      throw std::runtime_error("--backend cuda: this build has no CUDA backend (configured without nvcc)");
#endif
    // No GPU: cpu_threads, which gives cpu_double's bytes on every core.
    return make_cpu_threads_backend(options.threads);
  }
  throw std::invalid_argument("unknown backend '" + name + "'");
}

std::string resolve_backend_name(const std::string &name, BackendOptions *options) {
  if (name == "cuda_exact" || name == "cuda_float") {
    options->cuda_mode = name == "cuda_exact" ? CudaMode::Exact : CudaMode::Float;
    return "cuda";
  }
  return name;
}

std::unique_ptr<Renderer> make_renderer(const std::string &backend, const BackendOptions &options) {
#if defined(VASCO_HAVE_CUDA)
  std::string why;
  if ((backend == "cuda" || backend == "auto") &&
      cuda_usable(options.cuda_device, &why))
    return make_cuda_renderer(options);
#endif
  return std::make_unique<HostRenderer>(make_backend(backend, options));
}

}  // namespace vasco
