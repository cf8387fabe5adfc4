// carmen_compat/atomic_file.h: several outputs committed together (an
// OutputTransaction): rename failures undone, the target locks, and
// termination signals held back until a commit is whole.
#include "carmen_compat/atomic_file.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "carmen_compat/error.h"
#include "carmen_compat/termination_signals.h"
#include "atomic_file_test_support.h"

namespace {

using namespace atomictest;

TEST(MapOutputTransaction, AFailureBeforeCommitTouchesNoOutput) {
  TempDir dir;
  write_text(dir.file("keep.map"), "old map");
  try {
    carmen::OutputTransaction tx;
    carmen::AtomicOutput &a = tx.add(dir.file("keep.map"));
    FILE *f = a.take_stdio();
    std::fputs("new map", f);
    std::fclose(f);
    tx.add(dir.file("x.png"));
    throw std::runtime_error("the second writer failed");
  } catch (const std::runtime_error &) {
  }
  EXPECT_EQ(read_text(dir.file("keep.map")), "old map");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.map"});
}

TEST(MapOutputTransaction, CommitRenamesEveryOutput) {
  TempDir dir;
  carmen::OutputTransaction tx;
  for (const char *name : {"a.map", "a.yaml"}) {
    FILE *f = tx.add(dir.file(name)).take_stdio();
    std::fputs(name, f);
    std::fclose(f);
  }
  tx.commit();
  EXPECT_EQ(read_text(dir.file("a.yaml")), "a.yaml");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"a.map", "a.yaml"}));
}

// --- What a target must be before anything is renamed -------------------------

// A rename that fails after others succeeded (EPERM: another user's file in
// a sticky /tmp; EBUSY: a bind-mounted target) undoes the earlier ones: the
// old files are back, a new one is gone, nothing hidden is left.
TEST(MapOutputTransaction, ALaterRenameFailureRestoresTheEarlierTargets) {
  for (const int err : {EPERM, EBUSY}) {
    TempDir dir;
    write_text(dir.file("mine.map"), "old map");
    write_text(dir.file("run.yaml"), "old yaml");
    carmen::OutputTransaction tx;
    add_output(tx, dir.file("mine.map"), "new map");
    add_output(tx, dir.file("run.pgm"), "new pgm");
    add_output(tx, dir.file("run.yaml"), "new yaml");
    carmen::OutputTransaction::fail_rename_for_testing(3, err);
    expect_refused([&] { tx.commit(); }, dir.file("run.yaml"), std::strerror(err));
    carmen::OutputTransaction::fail_rename_for_testing(0, 0);
    EXPECT_EQ(read_text(dir.file("mine.map")), "old map");
    EXPECT_EQ(read_text(dir.file("run.yaml")), "old yaml");
    EXPECT_EQ(dir.entries(), (std::vector<std::string>{"mine.map", "run.yaml"}));
  }
}

TEST(MapOutputTransaction, TheOldFilesGoOnceAllAreRenamed) {
  TempDir dir;
  write_text(dir.file("a.map"), "old");
  carmen::OutputTransaction tx;
  add_output(tx, dir.file("a.map"), "new a");
  add_output(tx, dir.file("b.png"), "new b");
  tx.commit();
  EXPECT_EQ(read_text(dir.file("a.map")), "new a");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"a.map", "b.png"}));
}

// One directory spelled several ways (a "./", a "//", a symlink to it) is
// locked once: the commit neither waits for itself nor fails.
TEST(MapOutputTransaction, OneDirectorySpelledTwoWaysIsLockedOnce) {
  TempDir dir;
  ASSERT_EQ(::symlink(dir.path().c_str(), dir.file("alias").c_str()), 0);
  carmen::OutputTransaction tx;
  tx.set_lock_timeout_ms(2000);
  add_output(tx, dir.file("x.map"), "x");
  add_output(tx, dir.path() + "/./x.png", "p");
  add_output(tx, dir.path() + "//y.pgm", "y");
  add_output(tx, dir.file("alias/z.png"), "z");
  const auto t0 = std::chrono::steady_clock::now();
  tx.commit();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(1));
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"alias", "x.map", "x.png", "y.pgm", "z.png"}));
}

TEST(MapOutputTransaction, TheSameTargetTwiceIsAUsageError) {
  TempDir dir;
  carmen::OutputTransaction tx;
  tx.add(dir.file("d.map"));
  try {
    tx.add(dir.path() + "/./d.map");
    ADD_FAILURE() << "the same output was accepted twice";
  } catch (const carmen::Error &e) {
    EXPECT_EQ(e.code(), carmen::ErrorCode::Usage);
    EXPECT_NE(std::string(e.what()).find("give each output once"), std::string::npos) << e.what();
  }
}

// Another writer holds the target's lock file: the commit gives up after the
// timeout, names the target, the lock file and the holder (here this very
// process) and renames nothing. A lock file left behind (its writer killed)
// is taken by the next commit, and removed.
TEST(MapOutputTransaction, AHeldLockTimesOutNamingTheHolder) {
  TempDir dir;
  write_text(dir.file("a.map"), "old");
  const int fd = ::open(dir.file(".a.map.lock").c_str(), O_RDONLY | O_CREAT | O_CLOEXEC, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  {
    carmen::OutputTransaction tx;
    tx.set_lock_timeout_ms(200);
    add_output(tx, dir.file("a.map"), "new");
    const auto t0 = std::chrono::steady_clock::now();
    expect_refused([&] { tx.commit(); }, dir.file("a.map"), "pid " + std::to_string(::getpid()));
    expect_refused([&] { tx.commit(); }, dir.file("a.map"), dir.file(".a.map.lock"));
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
  }
  ASSERT_EQ(::close(fd), 0);
  EXPECT_EQ(read_text(dir.file("a.map")), "old");
  EXPECT_EQ(carmen::OutputTransaction::kDefaultLockTimeoutMs, 10000);
  carmen::OutputTransaction later;
  add_output(later, dir.file("a.map"), "new");
  later.commit();
  EXPECT_EQ(read_text(dir.file("a.map")), "new");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"a.map"});
}

// Anyone who may read the output directory may flock it: that stops no
// commit there (the lock is a file of our own beside each target).
TEST(MapOutputTransaction, AFlockOnTheOutputDirectoryStopsNoCommit) {
  TempDir dir;
  write_text(dir.file("m.pgm"), "old");
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t holder = ::fork();
  ASSERT_GE(holder, 0);
  if (holder == 0) {  // a foreign process: holds the directory's flock until killed
    const int fd = ::open(dir.path().c_str(), O_RDONLY | O_DIRECTORY);
    if (fd < 0 || ::flock(fd, LOCK_EX) != 0 || ::write(ready[1], "l", 1) != 1) ::_exit(3);
    for (;;) ::pause();
  }
  ::close(ready[1]);
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  ::close(ready[0]);
  carmen::OutputTransaction tx;  // the default timeout: 10 s
  add_output(tx, dir.file("m.pgm"), "new pgm");
  add_output(tx, dir.file("m.yaml"), "new yaml");
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_NO_THROW(tx.commit());
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(1));
  ::kill(holder, SIGKILL);
  ::waitpid(holder, nullptr, 0);
  EXPECT_EQ(read_text(dir.file("m.pgm")), "new pgm");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"m.pgm", "m.yaml"}));
}

// During the renames each target's lock file is there: a regular file of
// mode 0600 (another user can neither open nor lock it); afterwards it is gone.
TEST(MapOutputTransaction, TheLockFileIsPrivateAndGoesAfterTheCommit) {
  TempDir dir;
  std::vector<std::string> seen;
  carmen::OutputTransaction::after_rename_for_testing([&] {
    struct stat st;
    for (const char *name : {".a.map.lock", ".a.png.lock"}) {
      if (::lstat(dir.file(name).c_str(), &st) != 0) seen.push_back(std::string(name) + " missing");
      else if (!S_ISREG(st.st_mode) || (st.st_mode & 0777) != 0600) seen.push_back(std::string(name) + " not 0600");
    }
  });
  carmen::OutputTransaction tx;
  add_output(tx, dir.file("a.map"), "m");
  add_output(tx, dir.file("a.png"), "p");
  tx.commit();
  carmen::OutputTransaction::after_rename_for_testing(nullptr);
  EXPECT_TRUE(seen.empty()) << seen.front();
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"a.map", "a.png"}));
}

// A writer waits for another that holds the target's lock, and goes on once
// that one removes its lock file and lets go (as every commit does).
TEST(MapOutputTransaction, WritersOfOneTargetTakeTurns) {
  TempDir dir;
  const std::string lock = dir.file(".t.map.lock");
  const int fd = ::open(lock.c_str(), O_RDONLY | O_CREAT | O_CLOEXEC, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  std::thread other([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ::unlink(lock.c_str());
    ::close(fd);
  });
  carmen::OutputTransaction tx;
  tx.set_lock_timeout_ms(5000);
  add_output(tx, dir.file("t.map"), "second");
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_NO_THROW(tx.commit());
  EXPECT_GE(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(250));
  other.join();
  EXPECT_EQ(read_text(dir.file("t.map")), "second");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"t.map"});
}

// A symlink planted under a lock file's name is never followed: the commit
// goes on without that lock, the link and what it points to stay as they were.
TEST(MapOutputTransaction, APlantedSymlinkForTheLockIsNeverFollowed) {
  TempDir dir;
  write_text(dir.file("victim"), "precious");
  ASSERT_EQ(::symlink(dir.file("victim").c_str(), dir.file(".a.map.lock").c_str()), 0);
  carmen::OutputTransaction tx;
  add_output(tx, dir.file("a.map"), "new");
  tx.commit();
  EXPECT_EQ(read_text(dir.file("a.map")), "new");
  EXPECT_EQ(read_text(dir.file("victim")), "precious");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{".a.map.lock", "a.map", "victim"}));
}

// A lock file of another user (mode 0600: we may not open it) stops our
// commit only while someone holds it; one left behind by a killed writer
// does not stop us for good. Root opens any file, so the writer is a child
// that gives up root.
TEST(MapOutputTransaction, AnotherUsersLockFileStopsUsOnlyWhileHeld) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to make a file of another user";
  TempDir dir;
  ASSERT_EQ(::chmod(dir.path().c_str(), 0777), 0);
  const int fd = ::open(dir.file(".a.map.lock").c_str(), O_RDONLY | O_CREAT | O_CLOEXEC, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  // 0: committed; 10: timed out naming this process as the holder; else: something else.
  auto commit_as_nobody = [&] {
    const pid_t child = ::fork();
    if (child < 0) return -2;
    if (child == 0) {
      if (::setuid(65534) != 0) ::_exit(3);
      try {
        carmen::OutputTransaction tx;
        tx.set_lock_timeout_ms(300);
        FILE *f = tx.add(dir.file("a.map")).take_stdio();
        std::fputs("nobody's", f);
        std::fclose(f);
        tx.commit();
        ::_exit(0);
      } catch (const carmen::FileError &e) {
        ::_exit(std::string(e.what()).find("pid " + std::to_string(::getppid())) != std::string::npos ? 10 : 11);
      }
    }
    int status = -1;
    ::waitpid(child, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  EXPECT_EQ(commit_as_nobody(), 10);
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.map")));
  ASSERT_EQ(::close(fd), 0);  // the holder is gone, its lock file stays
  EXPECT_EQ(commit_as_nobody(), 0);
  EXPECT_EQ(read_text(dir.file("a.map")), "nobody's");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{".a.map.lock", "a.map"}));
}

// --- Signals during a commit -----------------------------------------------------

// A thread started by start_thread (as every thread of the library is) has
// the termination signals blocked; its creator's mask is as it was.
TEST(MapTerminationSignals, AThreadStartedByTheHelperBlocksThem) {
  auto blocked_here = [] {
    sigset_t mask;
    if (::pthread_sigmask(SIG_BLOCK, nullptr, &mask) != 0) return -1;
    return sigismember(&mask, SIGINT) + sigismember(&mask, SIGTERM) + sigismember(&mask, SIGHUP);
  };
  int in_thread = -2;
  std::thread t = carmen::start_thread([&] { in_thread = blocked_here(); });
  t.join();
  EXPECT_EQ(in_thread, 3);
  std::future<int> in_async = carmen::with_termination_signals_blocked(
      [&] { return std::async(std::launch::async, blocked_here); });
  EXPECT_EQ(in_async.get(), 3);
  EXPECT_EQ(blocked_here(), 0);  // the creator's mask is restored
}

// The parent's side of a child's commit that pauses after each rename: for
// each rename the child reports on `channel`, the parent sends it the next
// of `signals`, gives a thread that takes it time to run the handler, then
// lets the child go on. Returns the child's wait status.
int signal_after_each_rename(pid_t child, int channel, const std::vector<int> &signals) {
  char byte = 0;
  size_t sent = 0;
  while (::read(channel, &byte, 1) == 1) {
    ::kill(child, signals[sent++ % signals.size()]);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (::send(channel, "g", 1, MSG_NOSIGNAL) != 1) break;
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return status;
}

// In the child: after each rename, says so on `channel` and waits for the go.
void pause_after_each_rename(int channel) {
  carmen::OutputTransaction::after_rename_for_testing([channel] {
    char byte = 'r';
    if (::write(channel, &byte, 1) != 1 || ::read(channel, &byte, 1) != 1) ::_exit(5);
  });
}

// Commits a.map, a.pgm and a.yaml over old files in a forked child (the
// handlers installed) where `shape` runs `commit` on some thread, SIGTERM and
// SIGINT arriving after every rename; checks that the commit went whole and
// that the child then died of the first signal, leaving nothing hidden.
void expect_signals_wait_for_the_commit(const std::function<void(const std::function<void()> &)> &shape) {
  TempDir dir;
  const std::vector<std::string> names = {"a.map", "a.pgm", "a.yaml"};
  for (const std::string &n : names) write_text(dir.file(n), "old");
  int channel[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, channel), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(channel[0]);
    carmen::remove_temporaries_on_signals();
    pause_after_each_rename(channel[1]);
    shape([&] {
      carmen::OutputTransaction tx;
      for (const std::string &n : names) add_output(tx, dir.file(n), "new");
      tx.commit();
    });
    ::_exit(0);  // the signals that waited end the process before this
  }
  ::close(channel[1]);
  const int status = signal_after_each_rename(child, channel[0], {SIGTERM, SIGINT});
  ::close(channel[0]);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << "status " << status;
  for (const std::string &n : names) EXPECT_EQ(read_text(dir.file(n)), "new") << n;
  EXPECT_EQ(dir.entries(), names);
}

// A thread that does not block the signals (the application's own, or one
// started before they were blocked) takes them while the committing thread
// holds them back: its handler waits for the commit.
TEST(MapOutputTransaction, ASignalTakenByAnotherThreadWaitsForTheCommit) {
  expect_signals_wait_for_the_commit([](const std::function<void()> &commit) {
    std::thread([] {
      for (;;) ::pause();
    }).detach();
    commit();
  });
}

// Batch mode's shape: the commit runs on a pool thread (started blocking the
// signals) while the main thread, waiting, takes them: they wait too.
TEST(MapOutputTransaction, ASignalWaitsForACommitOnAThreadOfOurs) {
  expect_signals_wait_for_the_commit([](const std::function<void()> &commit) {
    std::thread pool = carmen::start_thread(commit);
    pool.join();
  });
}

}  // namespace
