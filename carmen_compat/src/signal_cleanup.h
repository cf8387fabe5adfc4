// The registry of live temporaries, for the files of ours atomic_file.cc and target_locks.cc make.
#ifndef CARMEN_COMPAT_SRC_SIGNAL_CLEANUP_H
#define CARMEN_COMPAT_SRC_SIGNAL_CLEANUP_H

#include <string>

namespace carmen::internal {

// Registers `path` (a file, or a directory removed once empty) for removal
// by the signal handlers (remove_temporaries_on_signals): its slot, or -1
// when it cannot be registered (too long, or every slot taken).
int register_temp(const std::string &path);

// Ends a registration register_temp made; -1 does nothing.
void unregister_temp(int slot);

}  // namespace carmen::internal

#endif  // CARMEN_COMPAT_SRC_SIGNAL_CLEANUP_H
