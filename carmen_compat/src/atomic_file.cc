// AtomicOutput: an exclusively created temp file in the target's directory +
// rename; OutputTransaction: several of them renamed together under a lock
// file of our own beside each target, undone should a later rename fail; the
// checks that a target can be replaced; the registry of live temporaries that
// the signal handlers remove, and the commit sections those handlers wait for.
#include "carmen_compat/atomic_file.h"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <random>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <tuple>

#include "carmen_compat/error.h"
#include "carmen_compat/input_file.h"
#include "carmen_compat/termination_signals.h"

namespace carmen {
namespace {

std::string errno_text(int err) { return std::strerror(err); }

// Splits "a/b/c.map" into "a/" and "c.map" (directory keeps its slash).
void split_path(const std::string &path, std::string *dir, std::string *base) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) {
    dir->clear();
    *base = path;
  } else {
    *dir = path.substr(0, slash + 1);
    *base = path.substr(slash + 1);
  }
}

// The directory a path's file lies in, fit for open() and stat().
std::string directory_of(const std::string &path) {
  std::string dir, base;
  split_path(path, &dir, &base);
  return dir.empty() ? std::string(".") : dir;
}

std::string file_name_of(const std::string &path) {
  std::string dir, base;
  split_path(path, &dir, &base);
  return base;
}

bool fsync_path(const std::string &path, bool directory) {
  const int fd = ::open(path.c_str(), directory ? (O_RDONLY | O_DIRECTORY) : O_RDONLY);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

FileError io_error(const std::string &path, const std::string &why) { return FileError(path, why, ErrorCode::Io); }

// --- Names -----------------------------------------------------------------
std::mutex name_mutex;
std::function<std::string()> &name_source() {
  static std::function<std::string()> s;
  return s;
}

std::string random_part() {
  std::lock_guard<std::mutex> lock(name_mutex);
  if (name_source()) return name_source()();
  static std::mt19937_64 rng(std::random_device{}() ^ (static_cast<uint64_t>(::getpid()) << 20));
  static const char digits[] = "0123456789abcdefghijklmnopqrstuvwxyz";
  std::string s;
  for (int i = 0; i < 12; ++i) s += digits[rng() % 36];
  return s;
}

// ".NAME.ROLE.PID.RANDOM" beside `path`: hidden, never ending in the target's
// extension, so extension-based tools ignore it.
std::string hidden_name(const std::string &path, const char *role) {
  std::string dir, base;
  split_path(path, &dir, &base);
  return dir + "." + base + "." + role + "." + std::to_string(static_cast<long>(::getpid())) + "." + random_part();
}

// --- The registry of live temporaries ----------------------------------------
// Fixed slots a signal handler can read without locks or allocation: the
// temporaries, the lock files held, log2map's directory for the output '-'.
constexpr int kSlots = 128;
char slot_path[kSlots][PATH_MAX];
volatile sig_atomic_t slot_used[kSlots];
std::mutex slot_mutex;

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

// Tests only: called after each rename of a commit (inside its section).
std::mutex hook_mutex;
std::function<void()> &rename_hook() {
  static std::function<void()> hook;
  return hook;
}

std::function<void()> current_rename_hook() {
  std::lock_guard<std::mutex> lock(hook_mutex);
  return rename_hook();
}

// --- Renames (with the failure tests inject) ----------------------------------
std::atomic<int> renames_until_failure{0};
std::atomic<int> injected_errno{0};

// True (and errno set) when a test asked this rename to fail.
bool injected_failure() {
  if (renames_until_failure.load() <= 0) return false;
  if (--renames_until_failure != 0) return false;
  errno = injected_errno.load();
  return true;
}

int exchange_names(const std::string &a, const std::string &b) {
  return ::renameat2(AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), RENAME_EXCHANGE);
}

// --- What a rename cannot or must not replace --------------------------------
const char *kind_of_file(mode_t mode) { return file_kind_text(static_cast<unsigned>(mode)); }

// "/a/b\040c" in /proc/self/mountinfo is "/a/b c".
std::string unescape_mount_path(const std::string &s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\\' && i + 3 < s.size()) {
      out += static_cast<char>(std::strtol(s.substr(i + 1, 3).c_str(), nullptr, 8));
      i += 3;
    } else {
      out += s[i];
    }
  }
  return out;
}

// Whether `path` (its directory resolved) is a mount point: a file bind-
// mounted there cannot be renamed over (EBUSY). Best effort: false when the
// mount table cannot be read.
bool is_mount_point(const std::string &path) {
  char *dir = ::realpath(directory_of(path).c_str(), nullptr);
  if (dir == nullptr) return false;
  const std::string full = (std::string(dir) == "/" ? std::string() : std::string(dir)) + "/" + file_name_of(path);
  std::free(dir);
  std::ifstream mounts("/proc/self/mountinfo");
  std::string line;
  while (std::getline(mounts, line)) {
    std::istringstream fields(line);
    std::string id, parent, devno, root, mount_point;
    if ((fields >> id >> parent >> devno >> root >> mount_point) && unescape_mount_path(mount_point) == full)
      return true;
  }
  return false;
}

void check_directory(const std::string &path, const std::string &dir, struct stat *dir_st) {
  if (::stat(dir.c_str(), dir_st) != 0)
    throw io_error(path, "cannot write here: directory '" + dir + "' " +
                             (errno == ENOENT ? std::string("does not exist") : errno_text(errno)));
  if (!S_ISDIR(dir_st->st_mode)) throw io_error(path, "cannot write here: '" + dir + "' is not a directory");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw io_error(path, "cannot write here: directory '" + dir + "' is not writable (" + errno_text(errno) + ")");
}

// In a sticky directory only the file's owner, the directory's owner or root
// may replace a file (the rename fails EPERM).
bool sticky_forbids(const struct stat &dir_st, const struct stat &st) {
  const uid_t me = ::geteuid();
  return (dir_st.st_mode & S_ISVTX) != 0 && me != 0 && st.st_uid != me && dir_st.st_uid != me;
}

void check_existing_target(const std::string &path, const std::string &dir, const struct stat &dir_st) {
  struct stat st;
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return;  // a new file
    throw io_error(path, "cannot look at it: " + errno_text(errno));
  }
  struct stat target = st;
  if (S_ISLNK(st.st_mode) && ::stat(path.c_str(), &target) != 0) target = st;  // a dangling link: replaced
  if (!S_ISREG(target.st_mode) && !S_ISLNK(target.st_mode)) {
    if (S_ISDIR(target.st_mode)) throw io_error(path, "is a directory: cannot write there");
    throw io_error(path, std::string("is ") + kind_of_file(target.st_mode) +
                             ": only a regular file is replaced by an output");
  }
  if (sticky_forbids(dir_st, st))
    throw io_error(path, "belongs to another user in the sticky directory '" + dir + "': it cannot be replaced");
  if (st.st_dev != dir_st.st_dev || is_mount_point(path))
    throw io_error(path, "is a mount point: it cannot be replaced");
}

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

// Every target's lock of one commit, held until release().
class TargetLocks {
 public:
  TargetLocks(const std::vector<std::string> &paths, int timeout_ms) {
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
  ~TargetLocks() { release(); }
  TargetLocks(const TargetLocks &) = delete;
  TargetLocks &operator=(const TargetLocks &) = delete;

  void release() noexcept {
    const SignalsWait section;
    for (size_t i = locks_.size(); i-- > 0;) locks_[i]->release();
    locks_.clear();
  }

 private:
  std::vector<std::unique_ptr<TargetLock>> locks_;
};

}  // namespace

SignalsWait::SignalsWait() { enter_section(); }  // blocked_, a member, first: no handler here inside
SignalsWait::~SignalsWait() { leave_section(); }

void check_replaceable(const std::string &path) {
  const std::string base = file_name_of(path);
  if (base.empty() || base == "." || base == "..")
    throw FileError(path, "not a file name (cannot write to it)", ErrorCode::Io);
  const std::string dir = directory_of(path);
  struct stat dir_st;
  check_directory(path, dir, &dir_st);
  check_existing_target(path, dir, dir_st);
}

TargetKey target_key(const std::string &path) {
  TargetKey k;
  struct stat st;
  if (::stat(path.c_str(), &st) == 0) {
    k.has_file = true;
    k.file_dev = static_cast<unsigned long long>(st.st_dev);
    k.file_ino = static_cast<unsigned long long>(st.st_ino);
  }
  if (::stat(directory_of(path).c_str(), &st) == 0) {
    k.has_place = true;
    k.dir_dev = static_cast<unsigned long long>(st.st_dev);
    k.dir_ino = static_cast<unsigned long long>(st.st_ino);
    k.name = file_name_of(path);
  }
  return k;
}

bool same_target(const std::string &a, const std::string &b) {
  const TargetKey ka = target_key(a), kb = target_key(b);
  if (ka.has_file && kb.has_file && ka.file_dev == kb.file_dev && ka.file_ino == kb.file_ino) return true;
  return ka.has_place && kb.has_place && ka.name == kb.name && ka.dir_dev == kb.dir_dev && ka.dir_ino == kb.dir_ino;
}

void AtomicOutput::set_name_source_for_testing(std::function<std::string()> source) {
  std::lock_guard<std::mutex> lock(name_mutex);
  name_source() = std::move(source);
}

TemporaryOnSignal::TemporaryOnSignal(const std::string &path) : slot_(register_temp(path)) {}
TemporaryOnSignal::~TemporaryOnSignal() { unregister_temp(slot_); }

AtomicOutput::AtomicOutput(std::string final_path) : final_path_(std::move(final_path)) {
  check_replaceable(final_path_);  // before a temporary appears beside a device or in a directory we cannot use
  for (int attempt = 0; attempt < 100; ++attempt) {
    const std::string candidate = hidden_name(final_path_, "tmp");
    temp_path_ = candidate;  // allocated before the section: nothing in it throws once the file exists
    const SignalsWait section;  // a temporary made is a temporary registered, whatever thread a signal finds
    const int fd = ::open(candidate.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    const int err = errno;
    if (fd >= 0) {
      fd_ = fd;
      slot_ = register_temp(temp_path_);
      return;
    }
    temp_path_.clear();
    if (err != EEXIST) {
      throw FileError(final_path_, "cannot create a temporary file beside it (" + candidate + "): " +
                                       errno_text(err), ErrorCode::Io);
    }
  }
  throw FileError(final_path_, "cannot create a temporary file beside it: 100 names were taken", ErrorCode::Io);
}

AtomicOutput::~AtomicOutput() { abandon(); }

FILE *AtomicOutput::take_stdio() {
  const int fd = take_fd();
  FILE *f = ::fdopen(fd, "wb");
  if (f == nullptr) {
    const int err = errno;
    ::close(fd);
    throw FileError(final_path_, "cannot write " + temp_path_ + ": " + errno_text(err), ErrorCode::Io);
  }
  return f;
}

int AtomicOutput::take_fd() {
  if (fd_ < 0) throw std::logic_error("AtomicOutput: the temporary file of " + final_path_ + " was already taken");
  const int fd = fd_;
  fd_ = -1;
  return fd;
}

void AtomicOutput::abandon() noexcept {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  if (!committed_ && !temp_path_.empty()) {
    ::unlink(temp_path_.c_str());  // may be gone already: nothing to do then
    unregister_temp(slot_);
    slot_ = -1;
  }
}

void AtomicOutput::close_and_verify() {
  if (committed_) throw std::logic_error("AtomicOutput::commit called twice for " + final_path_);
  if (fd_ >= 0) {  // never taken: an empty file
    ::close(fd_);
    fd_ = -1;
  }
  struct stat st;
  if (::lstat(temp_path_.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
    const int err = errno;
    abandon();
    throw FileError(final_path_, "nothing was written (temporary file " + temp_path_ + " is missing or was replaced" +
                                     (err ? ": " + errno_text(err) : std::string()) + ")", ErrorCode::Io);
  }
}

// Keeps the old file under a hidden hard link, or, where the file system
// refuses links, swaps it with the temporary in one exchange.
AtomicOutput::Replaced AtomicOutput::replace_target() {
  Replaced r;
  struct stat st;
  r.existed = ::lstat(final_path_.c_str(), &st) == 0;
  const bool refused = injected_failure();
  if (r.existed && !refused) {
    const std::string kept = hidden_name(final_path_, "old");
    if (::link(final_path_.c_str(), kept.c_str()) == 0) {
      r.kept = kept;
    } else if (exchange_names(temp_path_, final_path_) == 0) {
      r.kept = temp_path_;
      r.exchanged = true;
      return r;
    }
  }
  if (refused || std::rename(temp_path_.c_str(), final_path_.c_str()) != 0) {
    const int err = errno;
    if (!r.kept.empty()) ::unlink(r.kept.c_str());
    abandon();
    throw FileError(final_path_, "cannot move the finished file into place: " + errno_text(err), ErrorCode::Io);
  }
  return r;
}

void AtomicOutput::undo(const Replaced &r) noexcept {
  if (r.exchanged) {
    exchange_names(temp_path_, final_path_);  // the old file back; the new one goes with the temporary
    ::unlink(temp_path_.c_str());
  } else if (!r.kept.empty()) {
    std::rename(r.kept.c_str(), final_path_.c_str());
  } else if (!r.existed) {
    ::unlink(final_path_.c_str());
  }  // else: the file system kept no old file to go back to
  committed_ = false;
  temp_path_.clear();
  unregister_temp(slot_);
  slot_ = -1;
}

void AtomicOutput::finish(const Replaced &r) noexcept {
  if (!r.kept.empty()) ::unlink(r.kept.c_str());
  committed_ = true;
  unregister_temp(slot_);
  slot_ = -1;
}

void AtomicOutput::commit(bool durable) {
  close_and_verify();
  if (durable && !fsync_path(temp_path_, false)) {
    const int err = errno;
    abandon();
    throw FileError(final_path_, "cannot sync the data to disk: " + errno_text(err), ErrorCode::Io);
  }
  try {
    check_replaceable(final_path_);
  } catch (...) {
    abandon();
    throw;
  }
  {
    const SignalsWait section;  // the old file is never left under its hidden name
    finish(replace_target());
  }
  if (durable && !fsync_path(directory_of(final_path_), true)) {
    throw FileError(final_path_, "written, but syncing its directory failed: " + errno_text(errno), ErrorCode::Io);
  }
}

void OutputTransaction::fail_rename_for_testing(int n, int err) {
  injected_errno = err;
  renames_until_failure = n;
}

void OutputTransaction::after_rename_for_testing(std::function<void()> hook) {
  std::lock_guard<std::mutex> lock(hook_mutex);
  rename_hook() = std::move(hook);
}

AtomicOutput &OutputTransaction::add(const std::string &final_path) {
  for (const auto &o : outputs_) {
    if (same_target(o->final_path(), final_path))
      throw Error(ErrorCode::Usage, final_path + ": the same file as the output " + o->final_path() +
                                        ": give each output once");
  }
  outputs_.push_back(std::make_unique<AtomicOutput>(final_path));
  return *outputs_.back();
}

void OutputTransaction::commit() {
  std::vector<std::string> paths;
  for (const auto &o : outputs_) paths.push_back(o->final_path());
  TargetLocks locks(paths, lock_timeout_ms_);
  // From here to the locks' release a signal waits: none lands between two
  // renames, between a rename and its undoing, or on a lock file held.
  const SignalsWait section;
  try {
    rename_all();
  } catch (...) {
    locks.release();
    throw;
  }
  locks.release();
}

void OutputTransaction::rename_all() {
  // What would make a rename fail is checked for every output before the
  // first one moves, so that a refused commit touches none.
  for (const auto &o : outputs_) o->close_and_verify();
  for (const auto &o : outputs_) check_replaceable(o->final_path());
  const std::function<void()> hook = current_rename_hook();
  std::vector<AtomicOutput::Replaced> done;
  try {
    for (const auto &o : outputs_) {
      done.push_back(o->replace_target());
      if (hook) hook();
    }
  } catch (const FileError &e) {
    for (size_t i = done.size(); i-- > 0;) outputs_[i]->undo(done[i]);
    if (done.empty()) throw;
    throw FileError(e.file(), e.line(), e.message() + " (the outputs renamed before it have their old files back)",
                    e.code());
  }
  for (size_t i = 0; i < done.size(); ++i) outputs_[i]->finish(done[i]);
}

void write_file_atomically(const std::string &path, std::string_view contents, bool durable) {
  AtomicOutput out(path);
  FILE *f = out.take_stdio();
  const size_t written = contents.empty() ? 0 : std::fwrite(contents.data(), 1, contents.size(), f);
  const int write_errno = errno;
  const bool close_ok = std::fclose(f) == 0;
  if (written != contents.size() || !close_ok) {
    throw FileError(path, "write failed: " + errno_text(written != contents.size() ? write_errno : errno),
                    ErrorCode::Io);
  }
  out.commit(durable);
}

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
