// cuda_check.h — one error-check macro for every CUDA call, RAII owners for
// device memory, pinned host memory, streams and events. Used by the kernels
// and the host side of the CUDA backend, both in vasco_gpu/src/cuda/.
#ifndef VASCO_CUDA_CHECK_H
#define VASCO_CUDA_CHECK_H

#include <cuda_runtime.h>

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

#include "carmen_compat/error.h"

namespace vasco {
namespace cuda {

// The project's error code of a CUDA failure: no device or a driver or
// build that cannot run here is NoGpu, a failed allocation OutOfMemory, any
// other failure Internal (nothing we foresaw).
inline carmen::ErrorCode error_code_of(cudaError_t code) {
  switch (code) {
    case cudaErrorNoDevice:
    case cudaErrorInvalidDevice:
    case cudaErrorInsufficientDriver:
    case cudaErrorNoKernelImageForDevice:
    case cudaErrorDevicesUnavailable:
      return carmen::ErrorCode::NoGpu;
    case cudaErrorMemoryAllocation:
      return carmen::ErrorCode::OutOfMemory;
    default:
      return carmen::ErrorCode::Internal;
  }
}

// A failed CUDA call: what() names the call, the file and line, and the error.
class CudaError : public carmen::Error {
 public:
  CudaError(cudaError_t code, const char *call, const char *file, int line)
      : carmen::Error(error_code_of(code), std::string(file) + ":" + std::to_string(line) + ": " + call +
                                               " failed: " + cudaGetErrorName(code) + " (" +
                                               cudaGetErrorString(code) + ")"),
        cuda_code_(code) {}
  cudaError_t cuda_code() const { return cuda_code_; }

 private:
  cudaError_t cuda_code_;
};

}  // namespace cuda
}  // namespace vasco

#define VG_CUDA_CHECK(call)                                                          \
  do {                                                                               \
    const cudaError_t vg_err_ = (call);                                              \
    if (vg_err_ != cudaSuccess) throw ::vasco::cuda::CudaError(vg_err_, #call, __FILE__, __LINE__); \
  } while (0)

// After a kernel launch: reports launch-configuration errors at once.
#define VG_CUDA_CHECK_LAUNCH() VG_CUDA_CHECK(cudaGetLastError())

namespace vasco {
namespace cuda {

// Device memory for `n` elements of T; freed on destruction.
template <class T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  explicit DeviceBuffer(size_t n) { resize(n); }
  ~DeviceBuffer() { reset(); }
  DeviceBuffer(const DeviceBuffer &) = delete;
  DeviceBuffer &operator=(const DeviceBuffer &) = delete;
  DeviceBuffer(DeviceBuffer &&o) noexcept : ptr_(o.ptr_), n_(o.n_) { o.ptr_ = nullptr; o.n_ = 0; }
  DeviceBuffer &operator=(DeviceBuffer &&o) noexcept {
    if (this != &o) {
      reset();
      std::swap(ptr_, o.ptr_);
      std::swap(n_, o.n_);
    }
    return *this;
  }
  // Reallocates when n differs (contents are not kept).
  void resize(size_t n) {
    if (n == n_) return;
    reset();
    if (n > 0) VG_CUDA_CHECK(cudaMalloc(reinterpret_cast<void **>(&ptr_), n * sizeof(T)));
    n_ = n;
  }
  void reset() noexcept {
    if (ptr_ != nullptr) cudaFree(ptr_);
    ptr_ = nullptr;
    n_ = 0;
  }
  T *get() const { return ptr_; }
  size_t size() const { return n_; }
  size_t bytes() const { return n_ * sizeof(T); }

 private:
  T *ptr_ = nullptr;
  size_t n_ = 0;
};

// Page-locked host memory (fast, truly asynchronous copies).
template <class T>
class PinnedBuffer {
 public:
  PinnedBuffer() = default;
  explicit PinnedBuffer(size_t n) { resize(n); }
  ~PinnedBuffer() { reset(); }
  PinnedBuffer(const PinnedBuffer &) = delete;
  PinnedBuffer &operator=(const PinnedBuffer &) = delete;
  void resize(size_t n) {
    if (n == n_) return;
    reset();
    if (n > 0) VG_CUDA_CHECK(cudaMallocHost(reinterpret_cast<void **>(&ptr_), n * sizeof(T)));
    n_ = n;
  }
  void reset() noexcept {
    if (ptr_ != nullptr) cudaFreeHost(ptr_);
    ptr_ = nullptr;
    n_ = 0;
  }
  T *get() const { return ptr_; }
  T &operator[](size_t i) const { return ptr_[i]; }
  size_t size() const { return n_; }

 private:
  T *ptr_ = nullptr;
  size_t n_ = 0;
};

class Stream {
 public:
  Stream() { VG_CUDA_CHECK(cudaStreamCreateWithFlags(&s_, cudaStreamNonBlocking)); }
  // A stream whose blocks the device schedules before those of streams of a
  // lower priority, whenever both wait for room on a multiprocessor.
  struct Highest {};
  explicit Stream(Highest) {
    int least = 0, greatest = 0;
    VG_CUDA_CHECK(cudaDeviceGetStreamPriorityRange(&least, &greatest));
    VG_CUDA_CHECK(cudaStreamCreateWithPriority(&s_, cudaStreamNonBlocking, greatest));
  }
  ~Stream() {
    if (s_ != nullptr) cudaStreamDestroy(s_);
  }
  Stream(const Stream &) = delete;
  Stream &operator=(const Stream &) = delete;
  cudaStream_t get() const { return s_; }
  void synchronize() const { VG_CUDA_CHECK(cudaStreamSynchronize(s_)); }

 private:
  cudaStream_t s_ = nullptr;
};

class Event {
 public:
  Event() { VG_CUDA_CHECK(cudaEventCreate(&e_)); }
  ~Event() {
    if (e_ != nullptr) cudaEventDestroy(e_);
  }
  Event(const Event &) = delete;
  Event &operator=(const Event &) = delete;
  cudaEvent_t get() const { return e_; }
  void record(cudaStream_t s) { VG_CUDA_CHECK(cudaEventRecord(e_, s)); }
  // Milliseconds from `start` to this event (both must have completed).
  float since(const Event &start) const {
    float ms = 0;
    VG_CUDA_CHECK(cudaEventElapsedTime(&ms, start.e_, e_));
    return ms;
  }

 private:
  cudaEvent_t e_ = nullptr;
};

}  // namespace cuda
}  // namespace vasco

#endif  // VASCO_CUDA_CHECK_H
