// task_pool.h — a fixed set of threads running queued tasks, urgent ones
// first (batch mode: writing a mapped input's outputs goes before reading
// the next input, so finished maps do not pile up in memory).
#ifndef VASCO_GPU_TOOLS_TASK_POOL_H
#define VASCO_GPU_TOOLS_TASK_POOL_H

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace cli {

class TaskPool {
 public:
  // `nice`: added to each thread's nice value (Linux: per thread; threads a
  // task starts inherit it), so that a thread outside the pool that the
  // pool feeds (batch mode's mappers) gets a core when it needs one.
  explicit TaskPool(int threads, int nice = 0);
  // Runs every task still queued, then joins the threads.
  ~TaskPool();
  TaskPool(const TaskPool &) = delete;
  TaskPool &operator=(const TaskPool &) = delete;

  // A task must not throw (it catches what it can fail with).
  void submit(std::function<void()> task, bool urgent = false);

 private:
  void work();

  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<std::function<void()>> urgent_, normal_;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace cli

#endif  // VASCO_GPU_TOOLS_TASK_POOL_H
