// warp_sum.cuh — the sum over a full warp of one unsigned per lane, on every
// lane: sm_80's __reduce_add_sync where the device has it, five xor
// shuffles before (sm_75, T4). Unsigned sums wrap modulo 2^32 either way,
// so the result is the same on every architecture. The 64-bit sum takes the
// five shuffles everywhere (the reduction is 32-bit only).
#ifndef VASCO_CUDA_WARP_SUM_CUH
#define VASCO_CUDA_WARP_SUM_CUH

namespace vasco {
namespace cuda {

__device__ __forceinline__ unsigned warp_sum(unsigned v) {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 800
  return __reduce_add_sync(0xffffffffu, v);
#else
  for (int offset = 16; offset > 0; offset >>= 1) v += __shfl_xor_sync(0xffffffffu, v, offset);
  return v;
#endif
}

__device__ __forceinline__ unsigned long long warp_sum(unsigned long long v) {
  for (int offset = 16; offset > 0; offset >>= 1) v += __shfl_xor_sync(0xffffffffu, v, offset);
  return v;
}

}  // namespace cuda
}  // namespace vasco

#endif  // VASCO_CUDA_WARP_SUM_CUH
