// timing.h — wall time of a phase, for the statistics every backend and tool reports.
#ifndef VASCO_GPU_TIMING_H
#define VASCO_GPU_TIMING_H

#include <chrono>

namespace vasco {

using SteadyClock = std::chrono::steady_clock;

// Seconds from `t0` to now.
inline double seconds_since(SteadyClock::time_point t0) {
  return std::chrono::duration<double>(SteadyClock::now() - t0).count();
}

}  // namespace vasco

#endif  // VASCO_GPU_TIMING_H
