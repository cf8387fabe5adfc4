// Atomic file output: write to a temporary file beside the target, then
// rename it over the target. A writer that fails or throws part-way leaves
// the target untouched (an old file stays as it was, a new one never appears).
#ifndef CARMEN_COMPAT_ATOMIC_FILE_H
#define CARMEN_COMPAT_ATOMIC_FILE_H

#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "carmen_compat/termination_signals.h"

namespace carmen {

// Usage:
//   AtomicOutput out(path);          // creates the temporary file
//   FILE *f = out.take_stdio();      ... write, fclose, check ...
//   out.commit();                    // rename(temp, path); throws carmen::FileError
// If commit() is never reached (an exception, an early return), the
// destructor removes the temporary file.
//
// The temporary file lies in the target's directory (rename() is atomic only
// within one file system) and is named ".NAME.tmp.PID.RANDOM": hidden and
// never ending in the target's extension, so extension-based tools ignore it.
// It is created exclusively (O_CREAT | O_EXCL | O_NOFOLLOW, mode 0666 less the
// umask), so a name planted by someone else who can write the directory (a
// file or a symlink) is never opened: another name is drawn instead. Write
// through the descriptor it was created with (take_stdio, take_fd), never by
// reopening the name.
class AtomicOutput {
 public:
  // Throws carmen::FileError(final_path, ...) when the path has no file name
  // (empty, or ending in '/'), check_replaceable refuses it, or the temporary
  // file cannot be created.
  explicit AtomicOutput(std::string final_path);
  ~AtomicOutput();  // removes the temporary file unless committed
  AtomicOutput(const AtomicOutput &) = delete;
  AtomicOutput &operator=(const AtomicOutput &) = delete;

  const std::string &final_path() const noexcept { return final_path_; }
  const std::string &temp_path() const noexcept { return temp_path_; }

  // The temporary file, open for writing; the caller owns what it gets
  // (fclose / close it before commit). Each may be taken once.
  FILE *take_stdio();
  int take_fd();

  // Renames the temporary file over the final path. The file must be
  // complete and closed. With durable = true the data and the directory entry
  // are fsync'ed too (slower; for files that must survive a power cut).
  // Throws carmen::FileError naming the final path when check_replaceable
  // refuses the target or the rename fails (the temporary file is then
  // removed). Calling it twice is an error
  // (std::logic_error).
  void commit(bool durable = false);
  bool committed() const noexcept { return committed_; }

  // Removes the temporary file now and gives up (what the destructor does).
  void abandon() noexcept;

  // Tests only: where temporary names' random parts come from (nullptr: the
  // default source).
  static void set_name_source_for_testing(std::function<std::string()> source);

 private:
  friend class OutputTransaction;
  // What replace_target() did, so that undo() can put the old file back.
  struct Replaced {
    std::string kept;         // the old file's hidden name; empty: none kept
    bool existed = false;     // the target existed before
    bool exchanged = false;   // kept is the temporary's name (an exchange)
  };
  void close_and_verify();    // the temporary must be a complete regular file
  Replaced replace_target();  // the rename (throws carmen::FileError)
  void undo(const Replaced &r) noexcept;
  void finish(const Replaced &r) noexcept;  // removes the kept old file

  std::string final_path_;
  std::string temp_path_;
  int fd_ = -1;
  int slot_ = -1;  // in the registry of live temporaries (signal clean-up)
  bool committed_ = false;
};

// Several outputs as one transaction: every file is written to its
// temporary first and renamed only by commit(), when all are written; until
// then (an exception, a signal) no target is touched and the temporaries go.
//
// commit():
//  1. locks each target, with flock on a lock file of our own beside it
//     (".NAME.lock", created mode 0600, never through a symlink), in a fixed
//     order, so two concurrent runs writing the same pair of files (an image
//     and its YAML) leave both files from the same run. Not the directory: a
//     flock on it, which anyone who may read it can take, stops no commit. It
//     waits at most lock_timeout() (kDefaultLockTimeoutMs, 10 s) for another
//     holder, then fails naming the target, its lock file and, where
//     /proc/locks tells, the holder's pid. Each lock file goes again when its
//     commit is done (or on a signal); one a SIGKILL left is taken and
//     removed by the next commit. Where no lock can be had (a file system
//     without flock, something else under the name, another user's lock file
//     that nobody holds) the commit goes on without it;
//  2. checks every target with check_replaceable() before the first rename;
//  3. renames, keeping each old file under a hidden name (a hard link
//     ".NAME.old.PID.RANDOM", or the temporary's name by an atomic exchange
//     where hard links are refused): should a later rename fail, the earlier
//     targets get their old files back (a target that did not exist is
//     removed), and the error names the target that failed. Once all are
//     renamed the old files are removed.
// From the locks to their release SIGINT, SIGTERM and SIGHUP wait: they are
// held back on the committing thread, and remove_temporaries_on_signals's
// handler, on whatever thread a signal lands, lets the commits in progress
// (of every thread) end before it ends the process (SignalsWait, below).
// The threads the library starts block them (start_thread,
// termination_signals.h).
class OutputTransaction {
 public:
  static constexpr int kDefaultLockTimeoutMs = 10000;

  // Throws carmen::Error(ErrorCode::Usage) when `final_path` names a target
  // this transaction already has (see same_target), or AtomicOutput's errors.
  AtomicOutput &add(const std::string &final_path);
  void commit();

  void set_lock_timeout_ms(int ms) { lock_timeout_ms_ = ms; }
  int lock_timeout_ms() const { return lock_timeout_ms_; }

  // Tests only: the n-th rename (1-based) of the next commit in this process
  // fails with `err` as if the file system had refused it; 0 disarms.
  static void fail_rename_for_testing(int n, int err);
  // Tests only: `hook` runs after each rename of every commit in this process
  // (inside the commit, signals waiting); nullptr removes it.
  static void after_rename_for_testing(std::function<void()> hook);

 private:
  void rename_all();  // checks, renames (undone on a failure), and removes the old files

  std::vector<std::unique_ptr<AtomicOutput>> outputs_;
  int lock_timeout_ms_ = kDefaultLockTimeoutMs;
};

// Refuses, by throwing carmen::FileError(path, why, ErrorCode::Io), a target
// that a rename could not replace, or must not:
//  - its directory is missing, not a directory, or not writable (EROFS too);
//  - it exists and is not a regular file (a directory, a device such as
//    /dev/full, a FIFO, a socket; a symlink is judged by what it points to);
//  - it lies in a sticky directory (/tmp) and belongs to another user;
//  - it is a mount point (a bind-mounted file: the rename would fail EBUSY).
// AtomicOutput checks it when it is created and again before its rename.
void check_replaceable(const std::string &path);

// True when `a` and `b` name one target: the same name in the same directory
// (by device and inode), or one existing file (by device and inode, following
// symlinks). Paths that do not resolve are compared by nothing else: false.
bool same_target(const std::string &a, const std::string &b);

// What same_target compares, taken once a path (two or three stat calls), so
// that many paths are told apart in one pass: the file's device and inode
// where it exists, its place (its directory's device and inode, and its name)
// where the directory exists. Two paths are one target when either agrees.
struct TargetKey {
  bool has_file = false;
  unsigned long long file_dev = 0, file_ino = 0;
  bool has_place = false;
  unsigned long long dir_dev = 0, dir_ino = 0;
  std::string name;
};
TargetKey target_key(const std::string &path);

// Writes `contents` to `path` atomically (binary). Throws carmen::FileError.
void write_file_atomically(const std::string &path, std::string_view contents, bool durable = false);

// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove every live
// temporary file (and lock file held) of this process and then end it as the
// signal would have; during a commit, once the commits in progress are done
// (SIGKILL cannot be caught: it can leave a ".NAME.tmp.PID.RANDOM" behind).
// Idempotent. Throws std::system_error when the handlers cannot be installed.
void remove_temporaries_on_signals();

// A section of code that no termination signal cuts: while one lives, on
// any thread, SIGINT, SIGTERM and SIGHUP wait (held back on its own thread,
// and remove_temporaries_on_signals's handler, on whatever thread a signal
// lands, ends the process only once every section is left; no section starts
// once a signal waits). A commit's renames run in one; so should making a
// path and registering it with TemporaryOnSignal, so that no signal comes
// between the two. Keep it short: nothing inside may wait for another thread.
// Throws std::system_error when the signals cannot be blocked.
class SignalsWait {
 public:
  SignalsWait();
  ~SignalsWait();
  SignalsWait(const SignalsWait &) = delete;
  SignalsWait &operator=(const SignalsWait &) = delete;

 private:
  const TerminationSignalsBlocked blocked_;  // first in, last out
};

// A path of our own making that a fatal signal must not leave behind (a file,
// or a directory, removed once empty), registered with the temporaries above
// for the life of this object; what removes it otherwise is the owner's job.
class TemporaryOnSignal {
 public:
  explicit TemporaryOnSignal(const std::string &path);
  ~TemporaryOnSignal();
  TemporaryOnSignal(const TemporaryOnSignal &) = delete;
  TemporaryOnSignal &operator=(const TemporaryOnSignal &) = delete;

 private:
  int slot_;
};

}  // namespace carmen

#endif  // CARMEN_COMPAT_ATOMIC_FILE_H
