// The per-target lock files of a commit: taken in a fixed order, removed before they are let go.
#include "target_locks.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>
#include <tuple>

#include "atomic_file_support.h"
#include "carmen_compat/atomic_file.h"
#include "signal_cleanup.h"

namespace carmen {
namespace {

using internal::directory_of;
using internal::io_error;
using internal::register_temp;
using internal::split_path;
using internal::unregister_temp;

// --- Target locks ----------------------------------------------------------------
// Two of our writers committing the same target take turns, so that a pair
// (an image and its YAML) is left from one of them: each holds an exclusive
// flock on ".NAME.lock" beside every target while it renames. A lock file of
// our own, not the directory: anyone who may read a directory may flock it
// and so stop every writer there. The lock file is created mode 0600 (another
// user can neither open nor lock it) and never through a symlink; its holder
// removes it before letting go, so none is left behind, and a writer that
// gets the lock of a file already removed (or replaced) tries again.
struct FileKey {
  dev_t dev;
  ino_t ino;
};

bool same_file(const struct stat &a, const struct stat &b) { return a.st_dev == b.st_dev && a.st_ino == b.st_ino; }

// "pid 1234, log2map" of the process /proc/locks says holds a flock on the
// file (dev, ino); empty when it does not say.
std::string lock_holder(const FileKey &key) {
  char id[64];
  std::snprintf(id, sizeof id, "%02x:%02x:%lu", major(key.dev), minor(key.dev), static_cast<unsigned long>(key.ino));
  std::ifstream locks("/proc/locks");
  std::string line;
  while (std::getline(locks, line)) {
    std::istringstream fields(line);
    std::string number, type, advisory, mode, pid, file;
    if (!(fields >> number >> type >> advisory >> mode >> pid >> file) || type != "FLOCK" || file != id) continue;
    std::ifstream comm_file("/proc/" + pid + "/comm");
    std::string comm;
    std::getline(comm_file, comm);
    return "pid " + pid + (comm.empty() ? std::string() : ", " + comm);
  }
  return std::string();
}

// The lock of one target: its directory (open) and the lock file's name.
struct LockPlace {
  FileKey dir;
  int dir_fd;
  std::string name;    // ".NAME.lock"
  std::string path;    // as the target is spelled, for the registry and messages
  std::string target;
  bool operator<(const LockPlace &o) const {
    return std::tie(dir.dev, dir.ino, name) < std::tie(o.dir.dev, o.dir.ino, o.name);
  }
  bool operator==(const LockPlace &o) const { return dir.dev == o.dir.dev && dir.ino == o.dir.ino && name == o.name; }
};

// What one try at a lock file came to.
enum class LockTry {
  Held,      // locked, and the file is still the one named
  Busy,      // another writer holds it (ours, or another user's that we may not open)
  Again,     // the holder removed it as we opened it: try again at once
  Unusable,  // no lock here (no flock on this file system, something else under the name, another
             // user's lock file nobody holds): go on without
};

// The lock places of `paths`, each once, in a fixed order (by directory and
// name), so that two writers never wait for each other in a circle.
std::vector<LockPlace> lock_places(const std::vector<std::string> &paths) {
  std::vector<LockPlace> places;
  for (const std::string &p : paths) {
    std::string dir, base;
    split_path(p, &dir, &base);
    const int fd = ::open(directory_of(p).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) continue;  // the rename will say what is wrong
    struct stat st;
    if (::fstat(fd, &st) != 0) {
      ::close(fd);
      continue;
    }
    LockPlace place{FileKey{st.st_dev, st.st_ino}, fd, "." + base + ".lock", dir + "." + base + ".lock", p};
    if (std::find(places.begin(), places.end(), place) != places.end()) ::close(fd);
    else places.push_back(std::move(place));
  }
  std::sort(places.begin(), places.end());
  return places;
}

}  // namespace

namespace internal {

// A held lock file, registered for removal on a signal while it is held.
class TargetLock {
 public:
  // Takes the lock of `place` (closing its dir_fd in any case), waiting until
  // `deadline`; nullptr when the place has no usable lock. Throws
  // carmen::FileError naming the target when another writer holds it longer.
  static std::unique_ptr<TargetLock> take(const LockPlace &place, std::chrono::steady_clock::time_point deadline,
                                          int timeout_ms) {
    auto lock = std::unique_ptr<TargetLock>(new TargetLock(place));
    for (;;) {
      LockTry result;
      {
        const SignalsWait section;  // a lock file held is a lock file registered
        result = lock->try_once();
      }
      if (result == LockTry::Held) return lock;
      if (result == LockTry::Unusable) return nullptr;
      if (std::chrono::steady_clock::now() >= deadline) lock->time_out(timeout_ms);
      if (result == LockTry::Busy) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  ~TargetLock() { release(); }
  TargetLock(const TargetLock &) = delete;
  TargetLock &operator=(const TargetLock &) = delete;

  // Removes the lock file (ours: empty and regular) while still holding it,
  // then lets go. Inside a commit section, so that no signal finds the name
  // unregistered yet removed, or registered and already another writer's.
  void release() noexcept {
    if (fd_ >= 0) {
      // An unlink that fails (the name already gone, a read-only directory)
      // leaves an empty lock file at worst, which the next writer reuses.
      if (removable_ && still_named()) ::unlinkat(place_.dir_fd, place_.name.c_str(), 0);
      unregister_temp(slot_);
      slot_ = -1;
      ::close(fd_);  // closing releases the flock; nothing to do should it fail
      fd_ = -1;
    }
    if (place_.dir_fd >= 0) {
      ::close(place_.dir_fd);
      place_.dir_fd = -1;
    }
  }

 private:
  explicit TargetLock(const LockPlace &place) : place_(place) {}

  LockTry try_once() {
    const int fd = ::openat(place_.dir_fd, place_.name.c_str(),
                            O_RDONLY | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0600);
    if (fd < 0) return errno == EACCES && held_by_someone() ? LockTry::Busy : LockTry::Unusable;
    struct stat st;
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
      ::close(fd);
      return LockTry::Unusable;
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      ::close(fd);
      return err == EWOULDBLOCK || err == EINTR ? LockTry::Busy : LockTry::Unusable;
    }
    fd_ = fd;
    if (!still_named()) {  // the previous holder removed it before we locked it
      ::close(fd_);
      fd_ = -1;
      return LockTry::Again;
    }
    removable_ = st.st_size == 0 && st.st_uid == ::geteuid();  // a file of someone else's under our name stays
    if (removable_) slot_ = register_temp(place_.path);
    return LockTry::Held;
  }

  // Whether /proc/locks says someone holds a flock on the lock file we may
  // not open (another user's): a file nobody holds (its writer was killed)
  // must not stop us for good; we go on without it.
  bool held_by_someone() const {
    struct stat st;
    return ::fstatat(place_.dir_fd, place_.name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 &&
           !lock_holder(FileKey{st.st_dev, st.st_ino}).empty();
  }

  // Whether the name still leads to the file we hold.
  bool still_named() const {
    struct stat held, named;
    return ::fstat(fd_, &held) == 0 &&
           ::fstatat(place_.dir_fd, place_.name.c_str(), &named, AT_SYMLINK_NOFOLLOW) == 0 && same_file(held, named);
  }

  [[noreturn]] void time_out(int timeout_ms) const {
    struct stat st;
    std::string holder;
    if (::fstatat(place_.dir_fd, place_.name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0)
      holder = lock_holder(FileKey{st.st_dev, st.st_ino});
    char waited[32];
    std::snprintf(waited, sizeof waited, "%g s", timeout_ms / 1000.0);
    throw io_error(place_.target, "another writer holds its lock " + place_.path + " (" +
                                      (holder.empty() ? std::string("holder unknown") : holder) +
                                      ") for more than " + waited + ": nothing was written");
  }

  LockPlace place_;
  int fd_ = -1;
  int slot_ = -1;
  bool removable_ = false;
};

TargetLocks::TargetLocks(const std::vector<std::string> &paths, int timeout_ms) {
  std::vector<LockPlace> places = lock_places(paths);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  for (size_t i = 0; i < places.size(); ++i) {
    try {
      auto lock = TargetLock::take(places[i], deadline, timeout_ms);
      if (lock) locks_.push_back(std::move(lock));
    } catch (...) {
      for (size_t j = i + 1; j < places.size(); ++j) ::close(places[j].dir_fd);  // i's went with its lock
      release();
      throw;
    }
  }
}

TargetLocks::~TargetLocks() { release(); }

void TargetLocks::release() noexcept {
  const SignalsWait section;
  for (size_t i = locks_.size(); i-- > 0;) locks_[i]->release();
  locks_.clear();
}

}  // namespace internal
}  // namespace carmen
