// AtomicOutput: an exclusively created temp file in the target's directory +
// rename; OutputTransaction: several of them renamed together; the registry
// of live temporaries that the signal handlers remove.
#include "carmen_compat/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <random>
#include <set>
#include <stdexcept>

#include "carmen_compat/error.h"

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

bool fsync_path(const std::string &path, bool directory) {
  const int fd = ::open(path.c_str(), directory ? (O_RDONLY | O_DIRECTORY) : O_RDONLY);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

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

// --- The registry of live temporaries ----------------------------------------
// Fixed slots a signal handler can read without locks or allocation.
constexpr int kSlots = 64;
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

extern "C" void remove_temporaries_and_die(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (slot_used[i]) ::unlink(slot_path[i]);  // async-signal-safe
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

// An exclusive lock on a directory for the renames of one commit.
class DirectoryLock {
 public:
  explicit DirectoryLock(const std::string &dir) {
    fd_ = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd_ >= 0) ::flock(fd_, LOCK_EX);  // best effort: without it the renames still work
  }
  ~DirectoryLock() {
    if (fd_ >= 0) ::close(fd_);  // closing releases the lock
  }
  DirectoryLock(const DirectoryLock &) = delete;
  DirectoryLock &operator=(const DirectoryLock &) = delete;

 private:
  int fd_ = -1;
};

}  // namespace

void AtomicOutput::set_name_source_for_testing(std::function<std::string()> source) {
  std::lock_guard<std::mutex> lock(name_mutex);
  name_source() = std::move(source);
}

AtomicOutput::AtomicOutput(std::string final_path) : final_path_(std::move(final_path)) {
  std::string dir, base;
  split_path(final_path_, &dir, &base);
  if (base.empty() || base == "." || base == "..") {
    throw FileError(final_path_, "not a file name (cannot write to it)");
  }
  const std::string prefix = dir + "." + base + ".tmp." + std::to_string(static_cast<long>(::getpid())) + ".";
  for (int attempt = 0; attempt < 100; ++attempt) {
    const std::string candidate = prefix + random_part();
    const int fd = ::open(candidate.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd >= 0) {
      fd_ = fd;
      temp_path_ = candidate;
      slot_ = register_temp(temp_path_);
      return;
    }
    if (errno != EEXIST) {
      throw FileError(final_path_, "cannot create a temporary file beside it (" + candidate + "): " +
                                       errno_text(errno));
    }
  }
  throw FileError(final_path_, "cannot create a temporary file beside it: 100 names were taken");
}

AtomicOutput::~AtomicOutput() { abandon(); }

FILE *AtomicOutput::take_stdio() {
  const int fd = take_fd();
  FILE *f = ::fdopen(fd, "wb");
  if (f == nullptr) {
    const int err = errno;
    ::close(fd);
    throw FileError(final_path_, "cannot write " + temp_path_ + ": " + errno_text(err));
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

void AtomicOutput::commit(bool durable) {
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
                                     (err ? ": " + errno_text(err) : std::string()) + ")");
  }
  if (durable && !fsync_path(temp_path_, false)) {
    const int err = errno;
    abandon();
    throw FileError(final_path_, "cannot sync the data to disk: " + errno_text(err));
  }
  if (std::rename(temp_path_.c_str(), final_path_.c_str()) != 0) {
    const int err = errno;
    abandon();
    throw FileError(final_path_, "cannot move the finished file into place: " + errno_text(err));
  }
  committed_ = true;
  unregister_temp(slot_);
  slot_ = -1;
  if (durable) {
    std::string dir, base;
    split_path(final_path_, &dir, &base);
    if (!fsync_path(dir.empty() ? std::string(".") : dir, true)) {
      throw FileError(final_path_, "written, but syncing its directory failed: " + errno_text(errno));
    }
  }
}

AtomicOutput &OutputTransaction::add(const std::string &final_path) {
  outputs_.push_back(std::make_unique<AtomicOutput>(final_path));
  return *outputs_.back();
}

void OutputTransaction::commit() {
  std::set<std::string> dirs;
  for (const auto &o : outputs_) {
    std::string dir, base;
    split_path(o->final_path(), &dir, &base);
    dirs.insert(dir);
  }
  std::vector<std::unique_ptr<DirectoryLock>> locks;  // in a fixed order: no deadlock between runs
  for (const std::string &d : dirs) locks.push_back(std::make_unique<DirectoryLock>(d));
  // What would make a rename fail is checked for every output before the
  // first one moves, so that a refused commit touches none.
  for (const auto &o : outputs_) {
    struct stat st;
    if (::stat(o->final_path().c_str(), &st) == 0 && S_ISDIR(st.st_mode))
      throw FileError(o->final_path(), "is a directory: cannot write there");
  }
  for (const auto &o : outputs_) o->commit();
}

void write_file_atomically(const std::string &path, std::string_view contents, bool durable) {
  AtomicOutput out(path);
  FILE *f = out.take_stdio();
  const size_t written = contents.empty() ? 0 : std::fwrite(contents.data(), 1, contents.size(), f);
  const int write_errno = errno;
  const bool close_ok = std::fclose(f) == 0;
  if (written != contents.size() || !close_ok) {
    throw FileError(path, "write failed: " + errno_text(written != contents.size() ? write_errno : errno));
  }
  out.commit(durable);
}

void remove_temporaries_on_signals() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction sa;
    std::memset(&sa, 0, sizeof sa);
    sa.sa_handler = remove_temporaries_and_die;
    sigemptyset(&sa.sa_mask);
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &sa, nullptr);
  });
}

}  // namespace carmen
