// The termination signals (SIGINT, SIGTERM, SIGHUP) kept off the threads the
// library starts. A process-directed signal goes to any thread that does not
// block it; an output transaction's commit holds these signals back on its
// own thread (atomic_file.h), so that every other thread of ours must block
// them too, or one of them would run the handler in the middle of the commit.
// Every thread the library and the tools start is started through
// with_termination_signals_blocked (start_thread for a plain std::thread).
#ifndef CARMEN_COMPAT_TERMINATION_SIGNALS_H
#define CARMEN_COMPAT_TERMINATION_SIGNALS_H

#include <signal.h>

#include <thread>
#include <utility>

namespace carmen {

// SIGINT, SIGTERM and SIGHUP: those remove_temporaries_on_signals handles.
sigset_t termination_signals();

// Blocks the termination signals on the calling thread for its lifetime,
// then restores the thread's mask as it was. Throws std::system_error when
// the mask cannot be changed.
class TerminationSignalsBlocked {
 public:
  TerminationSignalsBlocked();
  ~TerminationSignalsBlocked();
  TerminationSignalsBlocked(const TerminationSignalsBlocked &) = delete;
  TerminationSignalsBlocked &operator=(const TerminationSignalsBlocked &) = delete;

 private:
  sigset_t old_;
};

// Runs `create` (which starts a thread: a std::thread, std::async with
// std::launch::async) with the termination signals blocked, and returns what
// it returns: a new thread inherits its creator's mask, so the thread it
// starts never takes them. The caller's mask is restored afterwards.
template <class Create>
auto with_termination_signals_blocked(Create &&create) -> decltype(create()) {
  const TerminationSignalsBlocked blocked;
  return std::forward<Create>(create)();
}

// std::thread(f, args...) that never takes the termination signals.
template <class F, class... Args>
std::thread start_thread(F &&f, Args &&...args) {
  return with_termination_signals_blocked(
      [&] { return std::thread(std::forward<F>(f), std::forward<Args>(args)...); });
}

}  // namespace carmen

#endif  // CARMEN_COMPAT_TERMINATION_SIGNALS_H
