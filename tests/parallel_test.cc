// run_on_threads: every index once, fn(0) on the caller, the first exception
// rethrown, and calls made while the pool is busy (nested, or from several
// threads at once) still complete.
#include <gtest/gtest.h>

#include <atomic>
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

TEST(Parallel, HardwareThreadsIsPositiveAndStable) {
  EXPECT_GE(hardware_threads(), 1);
  EXPECT_EQ(hardware_threads(), hardware_threads());
}

}  // namespace
}  // namespace vasco
