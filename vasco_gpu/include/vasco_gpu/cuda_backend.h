// cuda_backend.h — the CUDA backend (only in builds configured with nvcc).
#ifndef VASCO_GPU_CUDA_BACKEND_H
#define VASCO_GPU_CUDA_BACKEND_H

#include <cstddef>
#include <memory>
#include <string>

#include "vasco_gpu/backend.h"

// CUDA's stream type without CUDA's headers: cudaStream_t is CUstream_st *.
struct CUstream_st;

namespace vasco {

// Whether CUDA device `device` can be used; initialises the CUDA context on
// the first call (a few tenths of a second: log2map starts it on another
// thread while the log is parsed). Thread-safe; later calls for the same device
// return the cached answer. `why` (optional) receives the reason when it cannot.
bool cuda_usable(int device, std::string *why);

// cudaGetDeviceCount's count, 0 when it fails (no driver, no device).
int cuda_visible_device_count();

// The device's name and memory, for messages ("NVIDIA H100 80GB HBM3, 79 GiB").
std::string cuda_device_description(int device);

// The device's free and total memory now (cudaMemGetInfo on `device`, which
// becomes the current device); false, and nothing set, when CUDA cannot say.
bool cuda_memory_info(int device, size_t *free_bytes, size_t *total_bytes);

class Renderer;
// A mapping session's renderer on the GPU (vasco::Mapper with backend "cuda"):
// grid, ranges and scratch resident between calls. options.cuda_mode Float:
// single precision, scans fused (fast); Exact: GRIDMAP bit-identical to
// cpu_double. `stream` (a cudaStream_t of options.cuda_device), when given,
// carries all of the renderer's work and is not destroyed by it (the caller
// keeps it alive while the renderer lives); without one the renderer owns
// its own. Every call returns with the stream idle. Throws vasco::Error
// (ErrorCode::NoGpu) without a usable GPU.
std::unique_ptr<Renderer> make_cuda_renderer(const BackendOptions &options, CUstream_st *stream = nullptr);

}  // namespace vasco

#endif  // VASCO_GPU_CUDA_BACKEND_H
