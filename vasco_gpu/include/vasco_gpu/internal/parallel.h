// parallel.h — the small thread helper the multi-threaded host code shares.
#ifndef VASCO_GPU_PARALLEL_H
#define VASCO_GPU_PARALLEL_H

#include <functional>

namespace vasco {

// The cores this process may run on (at least 1): its CPU affinity mask and,
// under a cgroup v2 CPU quota (cpu.max), the quota rounded up.
// std::thread::hardware_concurrency() counts every core of the host, which
// in a container that was given 16 of 200 cores starts 200 threads per pass.
int hardware_threads();

// Runs fn(t) once for each t in [0, n), on up to n threads, fn(0) on the
// calling thread (the others may run there too: fn must not wait for another
// index); returns when all have returned and rethrows the first exception. The helpers come from a process-wide pool, started on
// first use and kept (a render places beams in several passes, and starting
// 15 threads per pass costs about as much as the pass); a call made while the
// pool is busy (nested or from another thread) starts its own threads.
void run_on_threads(int n, const std::function<void(int)> &fn);

}  // namespace vasco

#endif  // VASCO_GPU_PARALLEL_H
