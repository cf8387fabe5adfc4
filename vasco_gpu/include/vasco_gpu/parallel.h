// parallel.h — the small thread helper the multi-threaded host code shares.
#ifndef VASCO_GPU_PARALLEL_H
#define VASCO_GPU_PARALLEL_H

#include <algorithm>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace vasco {

// All cores (at least 1).
inline int hardware_threads() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

// Runs fn(t) for t in [0, n), fn(0) on the calling thread; rethrows the first
// exception.
template <class Fn>
inline void run_on_threads(int n, Fn &&fn) {
  if (n <= 1) {
    fn(0);
    return;
  }
  std::exception_ptr error;
  std::mutex error_mutex;
  auto body = [&](int t) {
    try {
      fn(t);
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(static_cast<size_t>(n - 1));
  try {
    for (int t = 1; t < n; ++t) pool.emplace_back(body, t);
  } catch (...) {
    for (auto &th : pool) th.join();
    throw;
  }
  body(0);
  for (auto &th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace vasco

#endif  // VASCO_GPU_PARALLEL_H
