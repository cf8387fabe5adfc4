// Whether a GPU is usable, and the CUDA renderer of a mapping session for
// its mode.
#include "vasco_gpu/cuda_backend.h"

#include <dlfcn.h>

#include <map>
#include <memory>
#include <mutex>
#include <sstream>

#include "cuda_check.h"
#include "cuda_exact_renderer.h"
#include "cuda_float_renderer.h"
#include "egrid_kernels.h"
#include "split_renderer.h"
#include "vasco_gpu/error.h"

namespace vasco {
namespace {

// Whether each device asked about is usable, decided once per device (the
// first question creates its context).
struct UsableState {
  bool usable = false;
  std::string why;
};

std::mutex &usable_mutex() {
  static std::mutex m;
  return m;
}

std::map<int, UsableState> &usable_states() {
  static std::map<int, UsableState> s;
  return s;
}

// Why cudaGetDeviceCount failed, in words for someone who may have no GPU
// at all: the runtime says "CUDA driver version is insufficient" also when
// there is no driver, so tell that case apart by whether the driver's
// library can be loaded.
std::string no_device_reason(cudaError_t err) {
  if (err == cudaErrorNoDevice) return "no GPU found (the NVIDIA driver sees no device)";
  if (err == cudaErrorInsufficientDriver) {
    void *driver = dlopen("libcuda.so.1", RTLD_LAZY | RTLD_LOCAL);
    if (driver == nullptr) return "no GPU found (no NVIDIA driver is installed: libcuda.so.1 cannot be loaded)";
    dlclose(driver);
    return std::string("the NVIDIA driver is older than this build's CUDA runtime (") + cudaGetErrorString(err) +
           "): update the driver";
  }
  return std::string("no GPU found (") + cudaGetErrorString(err) + ")";
}

// Why `device` cannot run this build's kernels, or "" when it can.
std::string unusable_reason(int device) {
  int count = 0;
  cudaError_t err = cudaGetDeviceCount(&count);
  if (err != cudaSuccess) return no_device_reason(err);
  if (device < 0 || device >= count)
    return "CUDA device " + std::to_string(device) + " does not exist (" + std::to_string(count) + " present)";
  cudaDeviceProp prop;
  err = cudaGetDeviceProperties(&prop, device);
  if (err == cudaSuccess) err = cudaSetDevice(device);
  if (err == cudaSuccess) err = cudaFree(nullptr);  // creates the context
  if (err != cudaSuccess)
    return "CUDA device " + std::to_string(device) + " is not usable (" + cudaGetErrorString(err) + ")";
  std::string image_why;
  if (!cuda::kernels_runnable_on_current_device(&image_why))
    return std::string(prop.name) + " (compute capability " + std::to_string(prop.major) + "." +
           std::to_string(prop.minor) + ") cannot run this build's kernels (" + image_why +
           "): rebuild with its architecture in CMAKE_CUDA_ARCHITECTURES";
  return "";
}

}  // namespace

int cuda_visible_device_count() {
  int count = 0;
  if (cudaGetDeviceCount(&count) != cudaSuccess) {
    (void)cudaGetLastError();
    return 0;
  }
  return count;
}

bool cuda_usable(int device, std::string *why) {
  std::lock_guard<std::mutex> lock(usable_mutex());
  auto found = usable_states().find(device);
  if (found == usable_states().end()) {
    UsableState s;
    s.why = unusable_reason(device);
    s.usable = s.why.empty();
    found = usable_states().emplace(device, s).first;
  }
  if (!found->second.usable && why != nullptr) *why = found->second.why;
  return found->second.usable;
}

std::string cuda_device_description(int device) {
  cudaDeviceProp prop;
  if (cudaGetDeviceProperties(&prop, device) != cudaSuccess) return "unknown device";
  std::ostringstream o;
  o << prop.name << ", " << prop.multiProcessorCount << " SMs, "
    << prop.totalGlobalMem / (1024.0 * 1024 * 1024) << " GiB";
  return o.str();
}

bool cuda_memory_info(int device, size_t *free_bytes, size_t *total_bytes) {
  size_t f = 0, t = 0;
  if (cudaSetDevice(device) != cudaSuccess || cudaMemGetInfo(&f, &t) != cudaSuccess) {
    (void)cudaGetLastError();
    return false;
  }
  if (free_bytes != nullptr) *free_bytes = f;
  if (total_bytes != nullptr) *total_bytes = t;
  return true;
}

std::unique_ptr<Renderer> make_cuda_renderer(const BackendOptions &options, CUstream_st *stream) {
  if (options.split_devices.size() > 1) {
    if (stream != nullptr)
      throw Error(ErrorCode::Usage, "a split render has a stream per device: it takes no caller's stream");
    return make_split_renderer(options);
  }
  BackendOptions one = options;
  if (one.split_devices.size() == 1) one.cuda_device = one.split_devices[0];
  one.split_devices.clear();
  std::string why;
  if (!cuda_usable(one.cuda_device, &why)) throw Error(ErrorCode::NoGpu, "no usable GPU: " + why);
  if (one.cuda_mode == CudaMode::Exact) return std::make_unique<CudaExactRenderer>(one, stream);
  return std::make_unique<CudaFloatRenderer>(one, stream);
}

}  // namespace vasco
