#include "vasco_gpu/internal/parallel.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "carmen_compat/termination_signals.h"
#include "carmen_compat/usable_cores.h"

namespace vasco {
namespace {

// Helper threads that sleep between calls. One call at a time (busy_); the
// workers take indices from next_, and the caller waits until every index is
// done and no worker still holds the job, so none can outlive its fn. They
// block the termination signals (start_thread): a signal must find a thread
// that lets an output's commit finish first.
class WorkerPool {
 public:
  // False (nothing run) if another call holds the pool.
  bool try_run(int n, const std::function<void(int)> &fn) {
    std::unique_lock<std::mutex> busy(busy_, std::try_to_lock);
    if (!busy.owns_lock()) return false;
    workers_.reserve(static_cast<size_t>(n - 1));  // a push_back that throws would drop a running thread
    while (static_cast<int>(workers_.size()) < n - 1) workers_.push_back(carmen::start_thread([this] { work(); }));
    {
      std::lock_guard<std::mutex> lock(m_);
      job_ = &fn;
      n_ = n;
      done_ = 0;
      error_ = nullptr;
      next_.store(1);
      ++generation_;
    }
    wake_.notify_all();
    run_index(fn, 0);
    for (int t; (t = next_.fetch_add(1)) < n;) run_index(fn, t);
    std::unique_lock<std::mutex> lock(m_);
    finished_.wait(lock, [&] { return done_ == n_ && active_ == 0; });
    job_ = nullptr;
    const std::exception_ptr error = error_;
    lock.unlock();
    if (error) std::rethrow_exception(error);
    return true;
  }

 private:
  void work() {
    uint64_t seen = 0;
    std::unique_lock<std::mutex> lock(m_);
    for (;;) {
      wake_.wait(lock, [&] { return generation_ != seen; });
      seen = generation_;
      if (!job_) continue;
      const std::function<void(int)> &fn = *job_;
      const int n = n_;
      ++active_;
      lock.unlock();
      for (int t; (t = next_.fetch_add(1)) < n;) run_index(fn, t);
      lock.lock();
      if (--active_ == 0 && done_ == n_) finished_.notify_all();
    }
  }

  void run_index(const std::function<void(int)> &fn, int t) {
    std::exception_ptr error;
    try {
      fn(t);
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(m_);
    if (error && !error_) error_ = error;
    if (++done_ == n_ && active_ == 0) finished_.notify_all();
  }

  std::mutex busy_, m_;
  std::condition_variable wake_, finished_;
  std::vector<std::thread> workers_;
  const std::function<void(int)> *job_ = nullptr;
  int n_ = 0, done_ = 0, active_ = 0;
  uint64_t generation_ = 0;
  std::exception_ptr error_;
  std::atomic<int> next_{0};
};

// The process's pool. Never destroyed: its threads sleep until exit. A
// forked child (whose copy has no threads) makes its own.
WorkerPool *process_pool() {
  static std::mutex m;
  static WorkerPool *pool = nullptr;
  static pid_t owner = 0;
  std::lock_guard<std::mutex> lock(m);
  if (!pool || owner != getpid()) {
    pool = new WorkerPool;
    owner = getpid();
  }
  return pool;
}

void run_on_new_threads(int n, const std::function<void(int)> &fn) {
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
  std::vector<std::thread> threads;
  threads.reserve(static_cast<size_t>(n - 1));
  try {
    for (int t = 1; t < n; ++t) threads.push_back(carmen::start_thread(body, t));
  } catch (...) {
    for (auto &th : threads) th.join();
    throw;
  }
  body(0);
  for (auto &th : threads) th.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace

int hardware_threads() {
  static const int n = carmen::usable_cores();
  return n;
}

void run_on_threads(int n, const std::function<void(int)> &fn) {
  if (n <= 1) {
    fn(0);
    return;
  }
  if (!process_pool()->try_run(n, fn)) run_on_new_threads(n, fn);
}

}  // namespace vasco
