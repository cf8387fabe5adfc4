// run_on_threads: every index once, fn(0) on the caller, the first exception
// rethrown, calls made while the pool is busy (nested, or from several
// threads at once) still complete, and the workers block the termination
// signals.
#include <gtest/gtest.h>
#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "vasco_gpu/internal/parallel.h"

namespace vasco {
namespace {

TEST(Parallel, EveryIndexRunsOnceAndIndexZeroOnTheCaller) {
  for (int rep = 0; rep < 200; ++rep) {
    const int n = 1 + rep % 9;
    std::vector<std::atomic<int>> runs(static_cast<size_t>(n));
    std::thread::id zero;
    run_on_threads(n, [&](int t) {
      runs[static_cast<size_t>(t)].fetch_add(1);
      if (t == 0) zero = std::this_thread::get_id();
    });
    for (int t = 0; t < n; ++t) ASSERT_EQ(runs[static_cast<size_t>(t)].load(), 1) << "n " << n << " t " << t;
    ASSERT_EQ(zero, std::this_thread::get_id());
  }
}

TEST(Parallel, TheFirstExceptionIsRethrownAfterEveryIndexReturned) {
  std::atomic<int> returned{0};
  EXPECT_THROW(run_on_threads(6,
                              [&](int t) {
                                returned.fetch_add(1);
                                if (t % 2) throw std::runtime_error("index " + std::to_string(t));
                              }),
               std::runtime_error);
  EXPECT_EQ(returned.load(), 6);
  std::atomic<int> after{0};
  run_on_threads(4, [&](int) { after.fetch_add(1); });  // the pool still serves
  EXPECT_EQ(after.load(), 4);
}

TEST(Parallel, NestedAndConcurrentCallsComplete) {
  std::atomic<long> sum{0};
  std::vector<std::thread> callers;
  for (int c = 0; c < 4; ++c)
    callers.emplace_back([&] {
      for (int rep = 0; rep < 50; ++rep)
        run_on_threads(3, [&](int) { run_on_threads(3, [&](int u) { sum.fetch_add(u + 1); }); });
    });
  for (auto &th : callers) th.join();
  EXPECT_EQ(sum.load(), 4L * 50 * 3 * (1 + 2 + 3));
}

// How many of SIGINT, SIGTERM and SIGHUP the calling thread blocks.
int termination_signals_blocked() {
  sigset_t mask;
  if (::pthread_sigmask(SIG_BLOCK, nullptr, &mask) != 0) return -1;
  return sigismember(&mask, SIGINT) + sigismember(&mask, SIGTERM) + sigismember(&mask, SIGHUP);
}

// Runs `n` indices each on a thread of its own (every index waits, at most
// 10 s, until all have started) and returns how many of the signals each
// thread other than the caller blocks.
std::vector<int> masks_of_other_threads(int n) {
  std::atomic<int> started{0};
  std::mutex m;
  std::vector<int> masks;
  const std::thread::id caller = std::this_thread::get_id();
  run_on_threads(n, [&](int) {
    started.fetch_add(1);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (started.load() < n && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
    if (std::this_thread::get_id() == caller) return;
    const int blocked = termination_signals_blocked();
    std::lock_guard<std::mutex> lock(m);
    masks.push_back(blocked);
  });
  return masks;
}

// The workers (the pool's, and those started while the pool is busy) block
// the termination signals: a signal finds a thread that lets a commit end
// first (carmen_compat/atomic_file.h), and the caller's mask is untouched.
TEST(Parallel, WorkersBlockTheTerminationSignals) {
  EXPECT_EQ(masks_of_other_threads(4), std::vector<int>(3, 3));
  std::vector<int> nested;
  run_on_threads(2, [&](int t) {
    if (t == 0) nested = masks_of_other_threads(3);  // the pool is busy: new threads
  });
  EXPECT_EQ(nested, std::vector<int>(2, 3));
  EXPECT_EQ(termination_signals_blocked(), 0);
}

TEST(Parallel, HardwareThreadsIsPositiveAndStable) {
  EXPECT_GE(hardware_threads(), 1);
  EXPECT_EQ(hardware_threads(), hardware_threads());
}

}  // namespace
}  // namespace vasco
