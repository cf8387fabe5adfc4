// The tools' task pool (vasco_gpu/app/task_pool.h): every task runs, and its
// threads run `nice` lower than the thread that made the pool, as do threads
// a task starts (batch mode's reads start an inflate thread each).
#include "task_pool.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <future>
#include <thread>

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace {

#if defined(__linux__)
int this_thread_nice() { return ::getpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid))); }
#endif

TEST(TaskPool, RunsEveryTaskBeforeItIsDestroyed) {
  std::atomic<int> ran{0};
  {
    cli::TaskPool pool(3);
    for (int i = 0; i < 100; ++i) pool.submit([&ran] { ++ran; }, i % 7 == 0);
  }
  EXPECT_EQ(ran.load(), 100);
}

TEST(TaskPool, ItsThreadsAndTheirsRunNicer) {
#if defined(__linux__)
  const int base = this_thread_nice();
  std::promise<std::pair<int, int>> seen;
  {
    cli::TaskPool pool(1, 5);
    pool.submit([&seen] {
      int started = -100;
      std::thread([&started] { started = this_thread_nice(); }).join();
      seen.set_value({this_thread_nice(), started});
    });
  }
  const std::pair<int, int> got = seen.get_future().get();
  EXPECT_EQ(got.first, std::min(base + 5, 19));
  EXPECT_EQ(got.second, got.first) << "a thread a task starts inherits its nice value";
  EXPECT_EQ(this_thread_nice(), base) << "the caller's own priority is unchanged";
#else
  GTEST_SKIP() << "per-thread nice values are Linux's";
#endif
}

}  // namespace
