// usable_cores.h — how many cores this process may run on: the scheduler's
// affinity mask, capped by cgroup v2's CPU quota (a container given 4 of a
// host's 64 cores). Here, beside termination_signals, because it asks the
// system a question by reading a file (/sys/fs/cgroup/cpu.max), and the
// engine above reads no file; the engine's thread pool sizes itself by it.
#ifndef CARMEN_COMPAT_USABLE_CORES_H
#define CARMEN_COMPAT_USABLE_CORES_H

namespace carmen {

// At least 1.
int usable_cores();

}  // namespace carmen

#endif  // CARMEN_COMPAT_USABLE_CORES_H
