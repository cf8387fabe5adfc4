// VG_HD: a function compiled for the host and, under nvcc, for the device
// too: the per-cell math written once for every backend (vasco_gpu's
// internal/egrid_math.h and finish_math.h, occupancy_value.h here).
#ifndef CARMEN_COMPAT_HOST_DEVICE_H
#define CARMEN_COMPAT_HOST_DEVICE_H

#if defined(__CUDACC__)
#define VG_HD __host__ __device__ __forceinline__
#else
#define VG_HD inline
#endif

#endif  // CARMEN_COMPAT_HOST_DEVICE_H
