// The log2map tool, run as a program, ended by signals: SIGTERM between the
// renames of a commit leaves all old or all new outputs; no temporary is
// left, the map to "-" included.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "log2map_test_support.h"
#include "map_test_support.h"

namespace {

using namespace log2maptest;

// --- SIGTERM in the middle of a commit ------------------------------------------

struct SignalledRun {
  int status = -1;  // the wait status; -1: not run, not watched, or not ended in two minutes
  int signals = 0;  // how many SIGTERMs were sent
};

// Sends SIGTERM to `child` for each old file kept aside among the events
// read from the inotify descriptor `watch`.
int signal_on_old_files(int watch, pid_t child) {
  alignas(struct inotify_event) char buf[8192];
  int sent = 0;
  ssize_t n;
  while ((n = ::read(watch, buf, sizeof buf)) > 0) {
    for (char *p = buf; p < buf + n;) {
      const auto *e = reinterpret_cast<const struct inotify_event *>(p);
      if (e->len > 0 && std::strstr(e->name, ".old.") != nullptr && ::kill(child, SIGTERM) == 0) ++sent;
      p += sizeof(struct inotify_event) + e->len;
    }
  }
  return sent;
}

// Runs log2map with `args` (its output to /dev/null) and sends it SIGTERM
// each time a commit keeps an old file aside (".NAME.old.PID.RANDOM" appears
// in `watched`): repeatedly, between the renames of a commit.
SignalledRun run_with_sigterms_during_commits(const std::vector<std::string> &args, const std::string &watched) {
  SignalledRun run;
  const int watch = ::inotify_init1(IN_CLOEXEC | IN_NONBLOCK);
  if (watch < 0) return run;
  if (::inotify_add_watch(watch, watched.c_str(), IN_CREATE) < 0) {
    ::close(watch);
    return run;
  }
  std::vector<std::string> argv_text = {std::string(VASCO_BIN_DIR) + "/log2map"};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char *> argv;
  for (std::string &a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t child = ::fork();
  if (child == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    if (null < 0 || ::dup2(null, STDOUT_FILENO) < 0 || ::dup2(null, STDERR_FILENO) < 0) ::_exit(126);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(2);
  while (child > 0) {
    struct pollfd p = {watch, POLLIN, 0};
    ::poll(&p, 1, 5);
    run.signals += signal_on_old_files(watch, child);
    int status = 0;
    if (::waitpid(child, &status, WNOHANG) == child) {
      run.status = status;
      break;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(child, SIGKILL);
      ::waitpid(child, &status, 0);
      break;
    }
  }
  ::close(watch);
  return run;
}

// Each name in `outputs` (in `dir`) holds "old" or none does: one commit,
// whole or not at all.
void expect_all_old_or_all_new(const TempDir &dir, const std::vector<std::string> &outputs, const std::string &what) {
  int old = 0;
  for (const std::string &name : outputs) old += maptest::read_bytes(dir.file(name)) == "old" ? 1 : 0;
  EXPECT_TRUE(old == 0 || old == static_cast<int>(outputs.size()))
      << what << ": " << old << " of " << outputs.size() << " outputs are old";
}

// No temporary, kept old file or lock file is left.
void expect_nothing_hidden(const TempDir &dir, const std::string &what) {
  for (const std::string &name : dir.entries()) EXPECT_NE(name[0], '.') << what << ": " << name << " left";
}

// Died of SIGTERM, or was done before the signal came (exit status 0).
bool ended_by_sigterm_or_done(int status) {
  return (WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) || (WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

// The outputs of one log2map run: twelve, so that the commit takes a while.
std::vector<std::string> many_outputs() {
  std::vector<std::string> names;
  for (int i = 0; i < 4; ++i)
    for (const char *ext : {".map", ".pgm", ".yaml"}) names.push_back("m" + std::to_string(i) + ext);
  return names;
}

// cpu_threads on several threads (its workers live on through the commit):
// SIGTERM between the renames waits for the commit, whatever thread takes
// it; the process then dies of it, its outputs all new, nothing hidden left.
TEST(Log2Map, SigtermsDuringTheCommitOfAThreadedRunLeaveAllOldOrAllNew) {
  const std::string log = std::string(VASCO_TEST_DATA_DIR) + "/logs/good.log";
  for (int round = 0; round < 5; ++round) {
    TempDir dir;
    std::vector<std::string> args = {"-q", "--backend", "cpu_threads", "--threads", "4", log};
    for (const std::string &name : many_outputs()) {
      maptest::write_bytes(dir.file(name), "old");
      if (name.find(".yaml") == std::string::npos) args.push_back(dir.file(name));
    }
    const SignalledRun run = run_with_sigterms_during_commits(args, dir.path());
    const std::string what = "round " + std::to_string(round);
    ASSERT_GT(run.signals, 0) << what;
    EXPECT_TRUE(ended_by_sigterm_or_done(run.status)) << what << ": status " << run.status;
    expect_all_old_or_all_new(dir, many_outputs(), what);
    expect_nothing_hidden(dir, what);
  }
}

// Batch mode: the commits run on the pool's threads (--jobs) while the main
// thread maps; a SIGTERM that the main thread takes waits for them too.
TEST(Log2Map, SigtermsDuringBatchCommitsLeaveEachInputAllOldOrAllNew) {
  const std::string log = std::string(VASCO_TEST_DATA_DIR) + "/logs/good.log";
  for (int round = 0; round < 3; ++round) {
    TempDir logs, dir;
    std::vector<std::string> args = {"-q", "--backend", "cpu_threads", "--threads", "2", "--jobs", "3",
                                     "--formats", "map,pgm,png", "--out-dir", dir.path()};
    std::vector<std::vector<std::string>> outputs;
    for (int i = 0; i < 8; ++i) {
      const std::string stem = "in" + std::to_string(i);
      std::filesystem::copy_file(log, logs.file(stem + ".log"));
      args.push_back(logs.file(stem + ".log"));
      outputs.push_back({stem + ".map", stem + ".pgm", stem + ".yaml", stem + ".png"});
      for (const std::string &name : outputs.back()) maptest::write_bytes(dir.file(name), "old");
    }
    const SignalledRun run = run_with_sigterms_during_commits(args, dir.path());
    const std::string what = "round " + std::to_string(round);
    ASSERT_GT(run.signals, 0) << what;
    EXPECT_TRUE(ended_by_sigterm_or_done(run.status)) << what << ": status " << run.status;
    for (const auto &one : outputs) expect_all_old_or_all_new(dir, one, what + ", " + one[0]);
    expect_nothing_hidden(dir, what);
  }
}

// SIGTERM during a run: no temporary is left, the process dies of the signal.
TEST(Log2Map, SigtermLeavesNoTemporary) {
  TempDir dir;
  const std::string fr079 = std::string(VASCO_LOGS_DIR) + "/fr079-complete.gfs.log.gz";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const std::string bin = std::string(VASCO_BIN_DIR) + "/log2map";
    ::execl(bin.c_str(), bin.c_str(), "--quiet", "--backend", "cpu_double", fr079.c_str(),
            dir.file("a.map").c_str(), dir.file("b.pgm").c_str(), static_cast<char *>(nullptr));
    ::_exit(127);
  }
  ::usleep(300 * 1000);  // parsing or mapping by now; the temporaries exist from the start of writing
  ::kill(child, SIGTERM);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  const std::vector<std::string> left = dir.entries();
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    EXPECT_EQ(left, (std::vector<std::string>{"a.map", "b.pgm", "b.yaml"}));  // it finished first
  } else {
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
    for (const auto &f : left) EXPECT_EQ(f.find(".tmp."), std::string::npos) << f;
  }
}

// When dash_output_signalled sends its signal.
enum class SignalWhen {
  TemporaryMade,  // the temporary directory for '-' appeared in TMPDIR: the map is being written there
  PipeFull,       // the map's first bytes are in the pipe, which nobody reads: the copy is blocked
};

// Runs log2map writing the map to '-', a pipe the test does not read, with
// TMPDIR = `tmp`, and sends it `sig` once `when` comes. Returns the wait
// status (-1: it could not be watched, or did not end in two minutes).
int dash_output_signalled(const std::string &tmp, int sig, SignalWhen when) {
  const int watch = ::inotify_init1(IN_CLOEXEC);
  if (watch < 0) return -1;
  int out[2];
  if (::inotify_add_watch(watch, tmp.c_str(), IN_CREATE) < 0 || ::pipe2(out, O_CLOEXEC) != 0) {
    ::close(watch);
    return -1;
  }
  const std::string bin = std::string(VASCO_BIN_DIR) + "/log2map";
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(out[0]);
    ::close(out[1]);
    ::close(watch);
    return -1;
  }
  if (child == 0) {
    if (::dup2(out[1], STDOUT_FILENO) < 0 || ::setenv("TMPDIR", tmp.c_str(), 1) != 0) ::_exit(126);
    ::execl(bin.c_str(), bin.c_str(), "-q", "--backend", "cpu_threads", "--threads", "2", kIntel.c_str(), "-",
            static_cast<char *>(nullptr));
    ::_exit(127);
  }
  ::close(out[1]);
  struct pollfd p = {when == SignalWhen::TemporaryMade ? watch : out[0], POLLIN, 0};
  int status = -1;
  if (::poll(&p, 1, 120 * 1000) == 1) ::kill(child, sig);
  else ::kill(child, SIGKILL);
  if (::waitpid(child, &status, 0) != child) status = -1;
  ::close(out[0]);
  ::close(watch);
  return status;
}

// The output "-" leaves nothing in the temporary directory, whether standard
// output takes the map, closes early (SIGPIPE) or a later output fails, or
// SIGTERM or SIGINT ends the run as soon as the temporary directory appears
// or while the map is copied to a pipe that nobody reads; the run dies of
// the signal.
TEST(Log2MapConventions, DashLeavesNoTemporaryWhateverHappens) {
  TempDir dir, tmp;
  const std::string env = "TMPDIR=" + tooltest::quote(tmp.path()) + " ";
  const std::string tool = tooltest::quote(std::string(VASCO_BIN_DIR) + "/log2map");
  const std::string log = tooltest::quote(kIntel);
  EXPECT_EQ(std::system((env + tool + " -q --backend cpu_threads " + log + " - > /dev/null").c_str()), 0);
  std::system((env + tool + " -q --backend cpu_threads " + log + " - | head -c 10 > /dev/null").c_str());
  std::system((env + tool + " -q " + log + " - " + tooltest::quote(dir.file("no/such/dir.map")) + " > /dev/null 2>&1")
                  .c_str());
  EXPECT_TRUE(tmp.entries().empty());
  for (int round = 0; round < 9; ++round) {  // the signal lands at a slightly different time in each
    const int sig = round % 2 ? SIGINT : SIGTERM;
    const SignalWhen when = round % 3 ? SignalWhen::TemporaryMade : SignalWhen::PipeFull;
    const std::string what = std::string(strsignal(sig)) +
                             (when == SignalWhen::TemporaryMade ? ", writing the temporary" : ", on the pipe") +
                             " (round " + std::to_string(round) + ")";
    TempDir fresh;
    const int status = dash_output_signalled(fresh.path(), sig, when);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << what << ": status " << status;
    const std::vector<std::string> left = fresh.entries();
    EXPECT_TRUE(left.empty()) << what << ": " << left.front() << " left";
  }
}

}  // namespace
