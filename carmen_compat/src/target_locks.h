// The lock files beside the targets of a commit, which OutputTransaction::commit holds while it renames.
#ifndef CARMEN_COMPAT_SRC_TARGET_LOCKS_H
#define CARMEN_COMPAT_SRC_TARGET_LOCKS_H

#include <memory>
#include <string>
#include <vector>

namespace carmen::internal {

class TargetLock;  // one target's lock file, held (target_locks.cc)

// Every target's lock of one commit, held until release().
// The constructor takes the locks of `paths` in a fixed order, waiting at
// most timeout_ms for another writer; throws carmen::FileError naming the
// target whose lock another writer holds longer (none is held then).
class TargetLocks {
 public:
  TargetLocks(const std::vector<std::string> &paths, int timeout_ms);
  ~TargetLocks();
  TargetLocks(const TargetLocks &) = delete;
  TargetLocks &operator=(const TargetLocks &) = delete;

  void release() noexcept;

 private:
  std::vector<std::unique_ptr<TargetLock>> locks_;
};

}  // namespace carmen::internal

#endif  // CARMEN_COMPAT_SRC_TARGET_LOCKS_H
