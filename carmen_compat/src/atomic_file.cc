// The output files and their transaction: AtomicOutput, OutputTransaction and the checks of a target.
#include "carmen_compat/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <random>
#include <sstream>
#include <stdexcept>

#include "atomic_file_support.h"
#include "carmen_compat/error.h"
#include "carmen_compat/input_file.h"
#include "signal_cleanup.h"
#include "target_locks.h"

namespace carmen {
namespace internal {

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

FileError io_error(const std::string &path, const std::string &why) { return FileError(path, why, ErrorCode::Io); }

}  // namespace internal

namespace {

using internal::directory_of;
using internal::io_error;
using internal::register_temp;
using internal::split_path;
using internal::TargetLocks;
using internal::unregister_temp;

std::string errno_text(int err) { return std::strerror(err); }

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

}  // namespace

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
}  // namespace carmen
