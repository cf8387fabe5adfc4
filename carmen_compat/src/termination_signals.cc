// The termination signals, and their blocking on the threads we start.
#include "carmen_compat/termination_signals.h"

#include <pthread.h>

#include <system_error>

namespace carmen {

sigset_t termination_signals() {
  sigset_t set;
  sigemptyset(&set);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&set, sig);
  return set;
}

TerminationSignalsBlocked::TerminationSignalsBlocked() {
  const sigset_t set = termination_signals();
  const int err = ::pthread_sigmask(SIG_BLOCK, &set, &old_);
  if (err != 0) throw std::system_error(err, std::generic_category(), "cannot block the termination signals");
}

// Restoring a mask read back from the kernel cannot fail (EINVAL is for a bad
// `how`), so the result is not checked.
TerminationSignalsBlocked::~TerminationSignalsBlocked() { ::pthread_sigmask(SIG_SETMASK, &old_, nullptr); }

}  // namespace carmen
