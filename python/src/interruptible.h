// interruptible.h — running a long C++ call so that Ctrl-C is seen while it
// runs. The call runs on a worker thread with the GIL released; the calling
// thread waits for it and, between waits, runs Python's signal handlers
// (PyErr_CheckSignals), so a handler runs within a poll period of the
// signal. A C++ call cannot be stopped half-way, so when a handler raises
// (KeyboardInterrupt), the wait goes on until the call has finished and
// then that exception is raised: the object the call worked on is left as
// the call left it (done, or unchanged if it failed), never half-changed,
// and the call's own result or error is dropped.
#ifndef VASCO_PY_INTERRUPTIBLE_H
#define VASCO_PY_INTERRUPTIBLE_H

#include <nanobind/nanobind.h>

#include <chrono>
#include <future>
#include <thread>
#include <utility>

#include "carmen_compat/termination_signals.h"

namespace vasco_py {

namespace nb = nanobind;

// How long the caller sleeps between looks at the signals.
constexpr std::chrono::milliseconds kSignalPoll{20};

// Runs `fn()` (which must not touch Python objects) as above and returns
// its result or rethrows its exception. Call with the GIL held.
template <typename Fn>
auto run_interruptible(Fn &&fn) -> decltype(fn()) {
  using Result = decltype(fn());
  std::packaged_task<Result()> task(std::forward<Fn>(fn));
  std::future<Result> done = task.get_future();
  bool interrupted = false;
  {
    // The termination signals blocked on the worker: they reach this thread, whose Python
    // handlers run between the waits (and the worker may be in an output commit).
    std::thread worker = carmen::start_thread(std::move(task));
    for (;;) {
      bool ready = false;
      {
        nb::gil_scoped_release release;
        ready = done.wait_for(kSignalPoll) == std::future_status::ready;
        if (ready) worker.join();
      }
      if (ready) break;
      // A raising handler leaves its exception set; no Python call is made
      // after that until it is raised below.
      if (!interrupted && PyErr_CheckSignals() != 0) interrupted = true;
    }
  }
  if (interrupted) throw nb::python_error();
  return done.get();
}

}  // namespace vasco_py

#endif  // VASCO_PY_INTERRUPTIBLE_H
