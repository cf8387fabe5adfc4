// mapconvert and mapdiff, run as programs, ended by signals: as log2map
// (log2map_signals_test.cc), no temporary is left, the map to "-" included,
// and the process dies of the signal.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <string>
#include <vector>

#include "carmen_compat/map_format.h"
#include "map_test_support.h"

namespace {

using maptest::TempDir;

// A map large enough (64 MB of cells) that writing it takes a while: the
// signal lands while its temporary is being written.
std::string write_big_map(const TempDir &dir) {
  carmen::MapToWrite w;
  w.grid = carmen::GridMap::filled(4000, 4000, 0.05, 0.25f);
  w.origin = carmen::GlobalOffset{500000.5, 5400000.25, 0};
  const std::string path = dir.file("big.map");
  carmen::write_map(path, w);
  return path;
}

// Runs `argv` (a tool of the build) with TMPDIR = `tmp`, its standard output
// a pipe the test does not read, and sends it `sig` as soon as something is
// made in `watched`. Returns the wait status (-1: it could not be watched,
// nothing was made there in two minutes, or it did not end).
int signalled_when_made(const std::vector<std::string> &args, const std::string &tmp, const std::string &watched,
                        int sig) {
  const int watch = ::inotify_init1(IN_CLOEXEC);
  if (watch < 0) return -1;
  int out[2];
  if (::inotify_add_watch(watch, watched.c_str(), IN_CREATE) < 0 || ::pipe2(out, O_CLOEXEC) != 0) {
    ::close(watch);
    return -1;
  }
  std::vector<std::string> text = args;
  text[0] = std::string(VASCO_BIN_DIR) + "/" + text[0];
  std::vector<char *> argv;
  for (std::string &a : text) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t child = ::fork();
  if (child == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    if (null < 0 || ::dup2(out[1], STDOUT_FILENO) < 0 || ::dup2(null, STDERR_FILENO) < 0 ||
        ::setenv("TMPDIR", tmp.c_str(), 1) != 0)
      ::_exit(126);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(out[1]);
  int status = -1;
  if (child > 0) {
    struct pollfd p = {watch, POLLIN, 0};
    ::kill(child, ::poll(&p, 1, 120 * 1000) == 1 ? sig : SIGKILL);
    if (::waitpid(child, &status, 0) != child) status = -1;
  }
  ::close(out[0]);
  ::close(watch);
  return status;
}

bool died_of(int status, int sig) { return WIFSIGNALED(status) && WTERMSIG(status) == sig; }

// mapconvert IN -: the map is staged in TMPDIR (vasco_stdout.XXXXXX/) and
// then copied out; SIGTERM or SIGINT while it is staged removes it.
TEST(MapconvertSignals, DashOutputLeavesNoTemporaryOnSigtermOrSigint) {
  TempDir inputs;
  const std::string big = write_big_map(inputs);
  for (int round = 0; round < 4; ++round) {
    const int sig = round % 2 ? SIGINT : SIGTERM;
    const std::string what = std::string(strsignal(sig)) + " (round " + std::to_string(round) + ")";
    TempDir tmp;
    const int status = signalled_when_made({"mapconvert", "-q", big, "-"}, tmp.path(), tmp.path(), sig);
    EXPECT_TRUE(died_of(status, sig)) << what << ": status " << status;
    const std::vector<std::string> left = tmp.entries();
    EXPECT_TRUE(left.empty()) << what << ": " << left.front() << " left";
  }
}

// mapconvert IN OUT.pgm: the pair's temporaries beside OUT go too.
TEST(MapconvertSignals, FileOutputLeavesNoTemporaryOnSigterm) {
  TempDir inputs, out;
  const std::string big = write_big_map(inputs);
  const int status =
      signalled_when_made({"mapconvert", "-q", big, out.file("m.pgm")}, out.path(), out.path(), SIGTERM);
  EXPECT_TRUE(died_of(status, SIGTERM) || (WIFEXITED(status) && WEXITSTATUS(status) == 0)) << status;
  for (const std::string &name : out.entries()) EXPECT_NE(name[0], '.') << name << " left";
}

// mapdiff --png: its picture's temporary goes too.
TEST(MapdiffSignals, PictureLeavesNoTemporaryOnSigterm) {
  TempDir inputs, out;
  const std::string big = write_big_map(inputs);
  const int status = signalled_when_made({"mapdiff", "--png", out.file("d.png"), big, big}, out.path(), out.path(),
                                         SIGTERM);
  EXPECT_TRUE(died_of(status, SIGTERM) || (WIFEXITED(status) && WEXITSTATUS(status) == 0)) << status;
  for (const std::string &name : out.entries()) EXPECT_NE(name[0], '.') << name << " left";
}

}  // namespace
