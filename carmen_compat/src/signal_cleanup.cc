// The registry of live temporaries that the signal handlers remove, and the commit sections they wait for.
#include "signal_cleanup.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstring>
#include <mutex>
#include <system_error>
#include <thread>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/termination_signals.h"

namespace carmen {
namespace {

// --- The registry of live temporaries ----------------------------------------
// Fixed slots a signal handler can read without locks or allocation: the
// temporaries, the lock files held, log2map's directory for the output '-'.
constexpr int kSlots = 128;
char slot_path[kSlots][PATH_MAX];
volatile sig_atomic_t slot_used[kSlots];
std::mutex slot_mutex;

}  // namespace

namespace internal {

int register_temp(const std::string &path) {
  if (path.size() >= PATH_MAX) return -1;
  std::lock_guard<std::mutex> lock(slot_mutex);
  for (int i = 0; i < kSlots; ++i) {
    if (slot_used[i]) continue;
    std::memcpy(slot_path[i], path.c_str(), path.size() + 1);
    slot_used[i] = 1;
    return i;
  }
  return -1;  // more than kSlots at once: not cleaned on a signal, still on unwinding
}

void unregister_temp(int slot) {
  if (slot < 0) return;
  std::lock_guard<std::mutex> lock(slot_mutex);
  slot_used[slot] = 0;
}

}  // namespace internal

namespace {

// Async-signal-safe. A path already gone (unlink's ENOENT) or a directory
// not yet empty (rmdir's ENOTEMPTY) needs nothing more: the results are not
// looked at.
void remove_registered() noexcept {
  for (int i = 0; i < kSlots; ++i)
    if (slot_used[i]) ::unlink(slot_path[i]);
  for (int i = 0; i < kSlots; ++i)
    if (slot_used[i]) ::rmdir(slot_path[i]);  // the directories, now that their files are gone
}

// Removes what is registered and ends the process as `sig` would, from the
// handler or from the last commit a signal waited for (async-signal-safe).
[[noreturn]] void die_of(int sig) noexcept {
  remove_registered();
  ::signal(sig, SIG_DFL);
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, sig);
  ::pthread_sigmask(SIG_UNBLOCK, &set, nullptr);  // a commit's thread holds it back
  ::raise(sig);
  ::_exit(128 + sig);  // not reached: the default action of these signals ends the process
}

// --- Sections the signals wait for (SignalsWait) -----------------------------------
// A commit must not be cut between its renames and their undoing, nor a file
// of ours (a temporary, a lock file) be left between being made and being
// registered, whatever thread the signal lands on: a process-directed signal
// goes to any thread that does not block it, and in batch mode the commits
// run on the pool's threads while the main thread maps. So the handler looks
// at commit_state first: inside a section (count > 0) it only marks the
// signal as waiting; the last thread to leave a section then ends the
// process. Lock-free atomics, shared with the handler.
constexpr int kSignalWaits = 1 << 30;  // a signal came during a section
constexpr int kEnding = 1 << 29;       // the process is ending: no section starts
constexpr int kCountMask = kEnding - 1;
std::atomic<int> commit_state{0};
std::atomic<int> waiting_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads commit_state");
thread_local int section_depth = 0;  // a section inside another on one thread counts once

extern "C" void remove_temporaries_and_die(int sig) {
  int expected = 0;
  waiting_signal.compare_exchange_strong(expected, sig);  // the first signal is the one the process dies of
  int state = commit_state.load();
  int next = 0;
  do {
    if (state & (kEnding | kSignalWaits)) return;  // the process is ending, or will once the sections are left
    next = (state & kCountMask) == 0 ? kEnding : (state | kSignalWaits);
  } while (!commit_state.compare_exchange_weak(state, next));
  if (next == kEnding) die_of(sig);
}

// A forked child has none of its parent's other threads, so none of their
// sections: it starts with none.
void reset_sections_in_child() {
  commit_state.store(0);
  waiting_signal.store(0);
}

// Until the process ends (another thread is ending it, or a signal waits for
// the sections in progress, whose last one ends it).
[[noreturn]] void wait_for_the_end() {
  for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
}

// SignalsWait's entry: counts this thread in (once, however nested), unless
// a signal already waits or the process is ending.
void enter_section() {
  if (section_depth++ > 0) return;
  int state = commit_state.load();
  do {
    if (state & (kEnding | kSignalWaits)) wait_for_the_end();  // no new section once a signal came
  } while (!commit_state.compare_exchange_weak(state, state + 1));
}

// SignalsWait's exit: the last thread out of its sections ends the process
// when a signal waited for them.
void leave_section() noexcept {
  if (--section_depth > 0) return;
  int state = commit_state.load();
  int next = 0;
  do {
    next = state - 1;
    if ((next & kCountMask) == 0 && (next & kSignalWaits)) next = kEnding;
  } while (!commit_state.compare_exchange_weak(state, next));
  if (next == kEnding) die_of(waiting_signal.load());  // the signal that waited for us
}

}  // namespace

SignalsWait::SignalsWait() { enter_section(); }  // blocked_, a member, first: no handler here inside
SignalsWait::~SignalsWait() { leave_section(); }

TemporaryOnSignal::TemporaryOnSignal(const std::string &path) : slot_(internal::register_temp(path)) {}
TemporaryOnSignal::~TemporaryOnSignal() { internal::unregister_temp(slot_); }

void remove_temporaries_on_signals() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction sa;
    std::memset(&sa, 0, sizeof sa);
    sa.sa_handler = remove_temporaries_and_die;
    sa.sa_mask = termination_signals();  // one handler at a time on a thread
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
      if (::sigaction(sig, &sa, nullptr) != 0)
        throw std::system_error(errno, std::generic_category(), "cannot handle the termination signals");
    }
    const int err = ::pthread_atfork(nullptr, nullptr, reset_sections_in_child);
    if (err != 0) throw std::system_error(err, std::generic_category(), "cannot handle the termination signals");
  });
}

}  // namespace carmen
