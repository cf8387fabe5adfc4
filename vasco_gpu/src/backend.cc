#include "vasco_gpu/backend.h"

#include <stdexcept>

#include "vasco_gpu/cpu_threads_backend.h"

#if defined(VASCO_HAVE_CUDA)
#include "vasco_gpu/cuda_backend.h"
#endif

namespace vasco {

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

}  // namespace vasco
