#include "task_pool.h"

#include <algorithm>
#include <cerrno>

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include "carmen_compat/termination_signals.h"

namespace cli {

namespace {

// Lowers the calling thread's priority by `nice` (best effort: a refusal
// leaves it as it was).
void lower_this_thread(int nice) {
#if defined(__linux__)
  if (nice <= 0) return;
  const id_t tid = static_cast<id_t>(::syscall(SYS_gettid));
  errno = 0;
  const int now = ::getpriority(PRIO_PROCESS, tid);
  if (errno == 0) (void)::setpriority(PRIO_PROCESS, tid, std::min(now + nice, 19));
#else
  (void)nice;
#endif
}

}  // namespace

TaskPool::TaskPool(int threads, int nice) {
  threads_.reserve(static_cast<size_t>(std::max(threads, 1)));
  // The termination signals blocked (start_thread): a batch's commits run
  // here, and a signal must wait for them (carmen_compat/atomic_file.h).
  for (int i = 0; i < std::max(threads, 1); ++i)
    threads_.push_back(carmen::start_thread([this, nice] {
      lower_this_thread(nice);
      work();
    }));
}

TaskPool::~TaskPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  ready_.notify_all();
  for (std::thread &t : threads_) t.join();
}

void TaskPool::submit(std::function<void()> task, bool urgent) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    (urgent ? urgent_ : normal_).push_back(std::move(task));
  }
  ready_.notify_one();
}

void TaskPool::work() {
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      ready_.wait(lock, [this] { return stopping_ || !urgent_.empty() || !normal_.empty(); });
      if (urgent_.empty() && normal_.empty()) return;  // stopping, and nothing left
      std::deque<std::function<void()>> &queue = urgent_.empty() ? normal_ : urgent_;
      task = std::move(queue.front());
      queue.pop_front();
    }
    task();
  }
}

}  // namespace cli
