// cuda_backend.h — the CUDA backend (only in builds configured with nvcc).
#ifndef VASCO_GPU_CUDA_BACKEND_H
#define VASCO_GPU_CUDA_BACKEND_H

#include <memory>
#include <string>

#include "vasco_gpu/backend.h"

namespace vasco {

// Whether CUDA device `device` can be used; initialises the CUDA context on
// the first call (a few tenths of a second: log2map starts it on another
// thread while the log is parsed). Thread-safe; later calls return the cached
// answer. `why` (optional) receives the reason when it cannot.
bool cuda_usable(int device, std::string *why);

// The device's name and memory, for messages ("NVIDIA H100 80GB HBM3, 79 GiB").
std::string cuda_device_description(int device);

// mode Float: single precision, scans fused (fast). mode Exact: GRIDMAP
// bit-identical to cpu_double. Throws std::runtime_error without a usable GPU.
std::unique_ptr<Backend> make_cuda_backend(const BackendOptions &options);

class Renderer;
// A mapping session's renderer on the GPU (vasco::Mapper with backend "cuda"):
// grid, ranges and scratch resident between calls. Throws without a usable GPU.
std::unique_ptr<Renderer> make_cuda_renderer(const BackendOptions &options);

}  // namespace vasco

#endif  // VASCO_GPU_CUDA_BACKEND_H
