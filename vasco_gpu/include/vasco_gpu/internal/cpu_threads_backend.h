// cpu_threads_backend.h — the multi-threaded CPU backend: a GRIDMAP
// bit-identical to cpu_double (the oracle), computed on all cores. It is the
// honest CPU baseline of the GPU benchmarks.
#ifndef VASCO_GPU_CPU_THREADS_BACKEND_H
#define VASCO_GPU_CPU_THREADS_BACKEND_H

#include <cstdint>
#include <memory>
#include <vector>

#include "vasco_gpu/renderer.h"

namespace vasco {

// The renderer is make_renderer("cpu_threads", options): options.threads <= 0
// means hardware_threads() (parallel.h: the cores this process may use).

// How the last apply() of a cpu_threads renderer split its work: the grid
// is cut into stripes of x columns, each updated by one thread at a time.
struct CpuThreadsLoad {
  int threads = 0;
  std::vector<int> stripe_begin;          // stripe s: columns [stripe_begin[s], stripe_begin[s + 1])
  std::vector<uint64_t> stripe_beams;     // beams walked in stripe s
  std::vector<uint64_t> stripe_updates;   // cell updates applied in stripe s
  std::vector<int> stripe_thread;         // the thread that ran stripe s
  std::vector<uint64_t> thread_updates;   // cell updates applied by each thread
  std::vector<double> thread_busy_s;      // time each thread spent on stripes
  double stripes_s = 0;                   // wall time of the stripe phase
};

// The load report of `renderer`'s last apply(); null when `renderer` is not a
// cpu_threads renderer or has not applied scans yet.
const CpuThreadsLoad *cpu_threads_load(const Renderer &renderer);

}  // namespace vasco

#endif  // VASCO_GPU_CPU_THREADS_BACKEND_H
