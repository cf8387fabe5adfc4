// The log2map tool, run as a program: outputs, exit codes, messages.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <iterator>
#include <unistd.h>
#include <sys/stat.h>
#include <signal.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/inotify.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "carmen_compat/map_file.h"
#include "vasco_gpu/params.h"
#include "map_test_support.h"
#include "sticky_dir.h"
#include "tool_support.h"
#include "test_support.h"

namespace {

using maptest::TempDir;

using tooltest::contains;
using tooltest::ToolRun;

ToolRun log2map(const std::vector<std::string> &args, bool with_stderr = true) {
  return tooltest::run_tool("log2map", args, with_stderr);
}

const std::string kIntel = std::string(VASCO_LOGS_DIR) + "/intel.gfs.log.gz";

std::string write_text(const TempDir &dir, const std::string &name, const std::string &text) {
  const std::string path = dir.file(name);
  std::ofstream(path) << text;
  return path;
}

TEST(Log2Map, VersionNamesTheBackends) {
  const ToolRun r = log2map({"--version"});
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(contains(r.output, "cpu_double")) << r.output;
  EXPECT_TRUE(contains(r.output, "cpu_float")) << r.output;
}

TEST(Log2Map, UsageErrorsExitTwo) {
  TempDir dir;
  EXPECT_EQ(log2map({}).status, 2);
  EXPECT_EQ(log2map({kIntel}).status, 2);
  EXPECT_EQ(log2map({"--no-such-flag", kIntel, dir.file("a.map")}).status, 2);
  EXPECT_EQ(log2map({"--backend", "gpu9000", kIntel, dir.file("a.map")}).status, 2);
  // --split-devices: GPU numbers, one render (not a batch), not with --device.
  const ToolRun split = log2map({"--split-devices", "0,x", kIntel, dir.file("a.map")});
  EXPECT_EQ(split.status, 2);
  EXPECT_TRUE(contains(split.output, "--split-devices '0,x'")) << split.output;
  EXPECT_EQ(log2map({"--split-devices", "0,1", "--out-dir", dir.file("maps"), kIntel}).status, 2);
  EXPECT_EQ(log2map({"--split-devices", "0,1", "--device", "0", kIntel, dir.file("a.map")}).status, 2);
  const ToolRun ext = log2map({kIntel, dir.file("a.jpeg")});
  EXPECT_EQ(ext.status, 2);
  EXPECT_TRUE(contains(ext.output, "a.jpeg")) << ext.output;
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Log2Map, WritesEveryFormatAndTheMapIsTheOraclesFinishedGrid) {
  TempDir dir;
  const ToolRun r = log2map({"--backend", "cpu_double", "--json", kIntel, dir.file("m.map.gz"),
                             dir.file("m.pgm"), dir.file("m.png"), dir.file("plain.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"m.map.gz", "m.pgm", "m.png", "m.yaml", "plain.map"}));
  EXPECT_TRUE(contains(r.output, "\"cell_updates\":")) << r.output;
  EXPECT_TRUE(contains(r.output, "910 scans")) << r.output;

  // The GRIDMAP equals finish(cpu_double) computed here, in process.
  const vasco::MapperParams params;
  const auto log = vasco::testing_support::load_log(kIntel, params);
  const auto cells = vasco::render_grid(*vasco::make_renderer("cpu_double"), log.batch, params, log.geo);
  const auto fin = vasco::finish_grid(cells.data(), log.geo.size_x, log.geo.size_y, log.geo.resolution,
                                      4, 20);
  for (const char *name : {"m.map.gz", "plain.map"}) {
    const carmen::MapFile mf = carmen::read_map_file(dir.file(name));
    ASSERT_TRUE(mf.gridmap.has_value());
    EXPECT_EQ(mf.gridmap->size_x, fin.size_x);
    EXPECT_EQ(mf.gridmap->size_y, fin.size_y);
    EXPECT_FLOAT_EQ(static_cast<float>(mf.gridmap->resolution), 0.1f);
    EXPECT_TRUE(mf.gridmap->cells == fin.cells) << name;
    ASSERT_TRUE(mf.offset.has_value());
    // OFFSET: the world position of cell (0,0)'s corner (first pose + crop).
    EXPECT_NEAR(mf.offset->x, log.geo.world_x(fin.min_x * 4.0), 1e-9);
    EXPECT_NEAR(mf.offset->y, log.geo.world_y(fin.min_y * 4.0), 1e-9);
    ASSERT_TRUE(mf.creator.has_value());
    EXPECT_EQ(mf.creator->origin, "intel.gfs.log.gz");
  }
  const std::string yaml = maptest::read_bytes(dir.file("m.yaml"));
  EXPECT_TRUE(contains(yaml, "image: m.pgm")) << yaml;
  EXPECT_TRUE(contains(yaml, "resolution: 0.1")) << yaml;
}

TEST(Log2Map, BadLogNamesFileAndLineAndLeavesNoOutput) {
  TempDir dir;
  const std::string log = write_text(dir, "bad.log",
                                     "FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1.0 host 1.0\n"
                                     "FLASER 3 1.0 abc 3.0 0 0 0 0 0 0 1.0 host 1.0\n");
  const ToolRun r = log2map({log, dir.file("out.map"), dir.file("out.png")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, "bad.log:2:")) << r.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"bad.log"}));
  // Lenient: the bad line is skipped and reported, the map is written.
  const ToolRun l = log2map({"--lenient", log, dir.file("out.map")});
  EXPECT_EQ(l.status, 0) << l.output;
  EXPECT_TRUE(contains(l.output, "skipped 1 bad line")) << l.output;
}

TEST(Log2Map, MissingLogIsAnError) {
  TempDir dir;
  const ToolRun r = log2map({dir.file("nope.log.gz"), dir.file("out.map")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, "nope.log.gz")) << r.output;
}

TEST(Log2Map, ParameterErrorsNameTheKeyAndWhere) {
  TempDir dir;
  const ToolRun cli = log2map({"--vasco_p_occ", "1.5", kIntel, dir.file("o.map")});
  EXPECT_EQ(cli.status, 2);  // a bad value on the command line is a usage error
  EXPECT_TRUE(contains(cli.output, "vasco_p_occ")) << cli.output;
  const std::string ini = write_text(dir, "bad.ini", "[*]\nvasco_resolution 0.05\nvasco_range_sure 20\n");
  const ToolRun f = log2map({"--param-file", ini, kIntel, dir.file("o.map")});
  EXPECT_EQ(f.status, 1);
  EXPECT_TRUE(contains(f.output, "bad.ini:3")) << f.output;
  EXPECT_TRUE(contains(f.output, "vasco_range_sure")) << f.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"bad.ini"}));
}

TEST(Log2Map, TyposInTheIniAreWarnedAbout) {
  TempDir dir;
  const std::string ini = write_text(dir, "typo.ini", "[*]\nvasco_p_ocupied 0.7\n");
  const ToolRun r = log2map({"--param-file", ini, "--vasco_num_scans", "20", kIntel, dir.file("o.map")});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "typo.ini:2")) << r.output;
  EXPECT_TRUE(contains(r.output, "vasco_p_ocupied")) << r.output;
  EXPECT_TRUE(contains(r.output, "20 scans")) << r.output;
}

TEST(Log2Map, UnwritableOutputFailsBeforeAnyWork) {
  TempDir dir;
  const ToolRun r = log2map({kIntel, dir.file("ok.map"), dir.file("no/such/dir/x.png")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, "x.png")) << r.output;
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Log2Map, CudaWithoutAGpuIsAClearError) {
  TempDir dir;
  const ToolRun v = log2map({"--backend", "cuda", "--vasco_num_scans", "5", kIntel, dir.file("o.map")});
  if (v.status == 0) GTEST_SKIP() << "a GPU is usable here: this checks the no-GPU error";
  EXPECT_EQ(v.status, 1);
  EXPECT_TRUE(contains(v.output, "backend cuda")) << v.output;
  // A CUDA build on a machine without a GPU (or driver) says so in plain
  // words, not in the runtime's "driver version is insufficient".
  if (!contains(v.output, "this build has no CUDA backend")) {
    EXPECT_TRUE(contains(v.output, "no GPU found")) << v.output;
  }
  EXPECT_TRUE(dir.entries().empty());
}


// The precedence every key follows, end to end: the log's PARAM lines select
// the scans unless the ini or the command line says otherwise.
TEST(Log2Map, LogParamsSelectScansBelowIniAndCommandLine) {
  TempDir dir;
  std::string text = "PARAM vasco_num_scans 3 nohost 0\n";
  for (int i = 0; i < 10; ++i)
    text += "FLASER 3 1.0 2.0 3.0 " + std::to_string(0.1 * i) + " 0 0 0 0 0 " + std::to_string(100 + i) + " t 0\n";
  const std::string log = write_text(dir, "p.log", text);
  const std::string ini = write_text(dir, "c.ini", "[*]\nvasco_num_scans 5\n");
  auto scans = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {"--backend", "cpu_double", "--json", "--quiet"});
    args.push_back(log);
    args.push_back(dir.file("out.map"));
    const ToolRun r = log2map(args, false);
    EXPECT_EQ(r.status, 0) << r.output;
    const size_t at = r.output.find("\"scans\":");
    return at == std::string::npos ? -1 : std::atoi(r.output.c_str() + at + 8);
  };
  EXPECT_EQ(scans({}), 3);
  EXPECT_EQ(scans({"--param-file", ini}), 5);
  EXPECT_EQ(scans({"--param-file", ini, "--vasco_num_scans", "7"}), 7);
}

// --resolution M: the written map's cell, by params.h's one rule. The maps
// it makes are compared with maps made by CARMEN's own keys, set by hand to
// what the rule says (0.1 = 0.025 x 4: vasco's defaults; 0.05 = 0.025 x 2;
// a given downsample 1: 0.05 x 1).
TEST(Log2Map, ResolutionSetsTheWrittenCellByOneRule) {
  TempDir dir;
  const auto grid = [&](const std::string &name, std::vector<std::string> args) {
    args.insert(args.begin(), {"--backend", "cpu_threads", "-q", kIntel, dir.file(name)});
    const ToolRun r = log2map(args);
    EXPECT_EQ(r.status, 0) << r.output;
    return *carmen::read_map_file(dir.file(name)).gridmap;
  };
  const auto same = [](const carmen::GridMap &a, const carmen::GridMap &b) {
    return a.size_x == b.size_x && a.size_y == b.size_y && float(a.resolution) == float(b.resolution) &&
           a.cells == b.cells;
  };
  EXPECT_TRUE(same(grid("a.map", {"--resolution", "0.1"}), grid("b.map", {})));
  const carmen::GridMap c = grid("c.map", {"--resolution", "0.05", dir.file("c.pgm")});
  EXPECT_FLOAT_EQ(float(c.resolution), 0.05f);
  EXPECT_TRUE(same(c, grid("d.map", {"--vasco_downsample", "2"})));
  EXPECT_TRUE(contains(maptest::read_bytes(dir.file("c.yaml")), "\nresolution: 0.05\n"));
  const std::string ini = write_text(dir, "one.ini", "[*]\nvasco_downsample 1\n");
  EXPECT_TRUE(same(grid("e.map", {"--param-file", ini, "--resolution", "0.05"}),
                   grid("f.map", {"--vasco_resolution", "0.05", "--vasco_downsample", "1"})));

  for (const std::vector<std::string> &bad : {std::vector<std::string>{"--resolution", "0"},
                                              {"--resolution", "abc"},
                                              {"--resolution", "inf"},
                                              {"--resolution", "1e-9"},
                                              {"--resolution", "0.05", "--vasco_resolution", "0.01"}}) {
    std::vector<std::string> args = bad;
    args.insert(args.end(), {kIntel, dir.file("bad.map")});
    const ToolRun r = log2map(args);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "resolution")) << r.output;
  }
  EXPECT_FALSE(maptest::file_exists(dir.file("bad.map")));
}

TEST(Log2Map, PosesTooFarApartNameTheLogAndLines) {
  TempDir dir;
  const std::string log = write_text(dir, "far.log",
                                     "FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1 t 0\n"
                                     "FLASER 3 1.0 2.0 3.0 50000000 0 0 0 0 0 2 t 0\n");
  const ToolRun r = log2map({"--backend", "cpu_double", log, dir.file("out.map")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, log + ": the poses span")) << r.output;
  EXPECT_TRUE(contains(r.output, "from the scan at line 1 to line 2 in x")) << r.output;
  EXPECT_TRUE(dir.entries() == (std::vector<std::string>{"far.log"}));
}


// A failing run touches no output: `keep.map` exists, `bad.png` is a
// directory; the run is refused before any work and keep.map stays as it was.
TEST(Log2Map, AFailingRunTouchesNoOutput) {
  TempDir dir;
  write_text(dir, "keep.map", "old contents");
  ASSERT_EQ(::mkdir(dir.file("bad.png").c_str(), 0755), 0);
  const ToolRun r = log2map({"--backend", "cpu_double", kIntel, dir.file("keep.map"), dir.file("bad.png")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, "bad.png: is a directory")) << r.output;
  std::ifstream in(dir.file("keep.map"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "old contents");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"bad.png", "keep.map"}));
}

// A PGM whose YAML cannot be written: neither file appears.
TEST(Log2Map, APgmWithoutItsYamlIsNeverWritten) {
  TempDir dir;
  ASSERT_EQ(::mkdir(dir.file("out.yaml").c_str(), 0755), 0);
  const ToolRun r = log2map({"--backend", "cpu_double", kIntel, dir.file("out.pgm")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, "out.yaml: is a directory")) << r.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"out.yaml"}));
}

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


// Two scans 399 m apart (diagonally) ask for a grid of 10^9 cells, 4.5 GiB
// on cpu_double: refused by the default memory budget before anything is
// allocated, naming the need, the bytes a cell and the scans that stretch it.
TEST(Log2Map, AGridBeyondTheMemoryBudgetIsRefusedNamingTheLog) {
  TempDir dir;
  const std::string log = write_text(dir, "far.log",
                                     "FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1 t 0\n"
                                     "FLASER 3 1.0 2.0 3.0 399 399 0 0 0 0 2 t 0\n");
  const ToolRun r = log2map({"--backend", "cpu_double", log, dir.file("out.map")});
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, log + ": the map needs about 4")) << r.output;
  EXPECT_TRUE(contains(r.output, "4.5 bytes a cell on cpu_double")) << r.output;
  EXPECT_TRUE(contains(r.output, "the poses span 798 m x 798 m (from the scan at line 1 to line 2 in x")) << r.output;
  EXPECT_TRUE(contains(r.output, "--max-memory")) << r.output;
  const ToolRun small = log2map({"--backend", "cpu_double", "--max-memory", "1", kIntel, dir.file("out.map")});
  EXPECT_EQ(small.status, 1);
  EXPECT_TRUE(contains(small.output, "more than the budget of 1 MiB")) << small.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"far.log"}));
}


// --max-memory bounds what is read too: a log of long scans is refused at
// the scan that passes the budget, naming the log's line, not loaded first
// (3000 scans of 100000 beams reached 2.8 GB with --max-memory 100).
TEST(Log2Map, TheMemoryBudgetIsCountedWhileTheLogIsRead) {
  TempDir dir;
  std::string scan = "FLASER 20000";
  for (int i = 0; i < 20000; ++i) scan += " 1.5";
  scan += " 0 0 0 0 0 0 1 t 0\n";
  std::string text;
  for (int i = 0; i < 40; ++i) text += scan;  // 80 KB of ranges a scan: 3.2 MB in all
  const std::string log = write_text(dir, "long.log", text);
  const ToolRun r = log2map({"--backend", "cpu_double", "--max-memory", "1", log, dir.file("out.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, log + ":1")) << r.output;  // a line of the log, "long.log:1N: ..."
  EXPECT_TRUE(contains(r.output, "(1.07 MiB), more than the memory budget of 1048576 bytes (1 MiB); raise it with "
                                 "--max-memory"))
      << r.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"long.log"}));
}

// A log whose every beam CARMEN skips (50 m or more, +inf, NaN, 1e308 as a
// float) maps nothing: the error names the log and says why (it said
// "gridmap size 0 x 0 is not positive", naming no file); nothing is written.
TEST(Log2Map, ALogWhoseEveryBeamIsSkippedSaysWhy) {
  TempDir dir;
  const std::string log = write_text(dir, "far.log",
                                     "FLASER 3 50.0 1e308 nan 0 0 0 0 0 0 1 t 0\n"
                                     "FLASER 3 60 inf 75.5 0.5 0 0 0.5 0 0 2 t 0\n");
  const ToolRun r = log2map({"--backend", "cpu_double", log, dir.file("out.map"), dir.file("out.png")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, log + ": no beam updated any cell: every one of the 6 ranges of the 2 scans"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "50 m or more, NaN or +inf")) << r.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"far.log"}));
}

// The small defects of the reliability audit, each with its reproduction.
TEST(Log2Map, SmallDefectsGiveClearErrors) {
  TempDir dir;
  // --threads 100000: a usage error, not a raw errno.
  EXPECT_EQ(log2map({"--threads", "100000", kIntel, dir.file("a.map")}).status, 2);
  // vasco_downsample larger than the grid and range_max 0 name the key.
  // Every bad --vasco_KEY value is the command line's fault, so a usage error
  // (exit 2), this one too, though it takes the log's grid to see it.
  const ToolRun ds = log2map({"--vasco_downsample", "1000000", kIntel, dir.file("a.map")});
  EXPECT_EQ(ds.status, 2);
  EXPECT_TRUE(contains(ds.output, "command line: vasco_downsample = 1000000 is larger than the grid")) << ds.output;
  const ToolRun rm = log2map({"--vasco_range_max", "0", kIntel, dir.file("a.map")});
  EXPECT_EQ(rm.status, 2);
  EXPECT_TRUE(contains(rm.output, "vasco_range_max = 0")) << rm.output;
  // vasco_first_scan near LONG_MAX: no overflow, a clear "nothing selected".
  const ToolRun fs = log2map({"--vasco_first_scan", "9223372036854775800", "--vasco_num_scans", "100", kIntel,
                              dir.file("a.map")});
  EXPECT_EQ(fs.status, 1);
  EXPECT_TRUE(contains(fs.output, "no FLASER or ROBOTLASER1 scans to map in the selected range")) << fs.output;
  EXPECT_TRUE(dir.entries().empty());
}

// A hostile file's escape sequences reach the terminal escaped.
TEST(Log2Map, EscapeCodesFromAFileAreNotEchoedRaw) {
  TempDir dir;
  const std::string ini = write_text(dir, "esc.ini", "[*]\nvasco_p_occ \x1b[31mRED\n");
  const ToolRun r = log2map({"--backend", "cpu_double", "--param-file", ini, kIntel, dir.file("out.map")});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.output.find('\x1b'), std::string::npos) << r.output;
  EXPECT_TRUE(contains(r.output, "\\x1b[31mRED")) << r.output;
}

// --- The output transaction, end to end ---------------------------------------

const std::vector<std::string> kFew = {"--backend", "cpu_double", "--quiet", "--vasco_num_scans", "20"};

ToolRun log2map_few(std::vector<std::string> args) {
  args.insert(args.begin(), kFew.begin(), kFew.end());
  return log2map(args);
}

std::string read_all(const std::string &path) { return maptest::read_bytes(path); }

// An output that is an input, or one output named twice: refused (usage)
// before anything is written; the input stays as it was.
TEST(Log2Map, AnOutputThatIsAnInputOrNamedTwiceIsRefused) {
  TempDir dir;
  const std::string log = write_text(dir, "run.yaml", "FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1 t 0\n");
  const ToolRun yaml = log2map_few({log, dir.file("run.pgm")});  // run.pgm writes run.yaml
  EXPECT_EQ(yaml.status, 2) << yaml.output;
  EXPECT_TRUE(contains(yaml.output, "is the input")) << yaml.output;
  EXPECT_EQ(read_all(log), "FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1 t 0\n");
  for (const std::string &again : {dir.file("d.map"), dir.path() + "/./d.map", dir.path() + "//d.map"}) {
    const ToolRun twice = log2map_few({kIntel, dir.file("d.map"), again});
    EXPECT_EQ(twice.status, 2) << again << "\n" << twice.output;
    EXPECT_TRUE(contains(twice.output, "give each output once")) << twice.output;
  }
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"run.yaml"}));
}

// One directory spelled two ways, or through a symlink, is locked once: the
// run ends (it waited on itself forever before).
TEST(Log2Map, OneDirectorySpelledTwoWaysDoesNotHang) {
  TempDir dir;
  ASSERT_EQ(::symlink(dir.path().c_str(), dir.file("alias").c_str()), 0);
  const ToolRun r = log2map_few({kIntel, dir.file("x.map"), dir.path() + "/./x.png", dir.path() + "//y.png",
                                 dir.file("alias/z.png")});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"alias", "x.map", "x.png", "y.png", "z.png"}));
}

// A carmen.ini or a pose file is read whole: a FIFO nobody writes blocked the
// open for ever; it is refused at once, named (a log may be a FIFO: the
// reader waits for its first byte, with a limit).
TEST(Log2Map, AFifoAsParamFileOrPoseFileIsRefusedNotWaitedFor) {
  TempDir dir;
  ASSERT_EQ(::mkfifo(dir.file("carmen.ini").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo(dir.file("poses.g2o").c_str(), 0600), 0);
  const ToolRun ini = log2map_few({"--param-file", dir.file("carmen.ini"), kIntel, dir.file("x.map")});
  EXPECT_EQ(ini.status, 1) << ini.output;
  EXPECT_TRUE(contains(ini.output, "carmen.ini: is a FIFO, not a regular file: a carmen.ini is read whole")) << ini.output;
  const ToolRun poses = log2map_few({"--poses", dir.file("poses.g2o"), kIntel, dir.file("x.map")});
  EXPECT_EQ(poses.status, 1) << poses.output;
  EXPECT_TRUE(contains(poses.output, "poses.g2o: is a FIFO, not a regular file: a pose file is read whole")) << poses.output;
  EXPECT_FALSE(maptest::file_exists(dir.file("x.map")));
}

// A device, a FIFO or a link to a device is not an output: refused before
// any work, and left as it was.
TEST(Log2Map, SpecialFilesAreNeverReplaced) {
  TempDir dir;
  ASSERT_EQ(::mkfifo(dir.file("p.png").c_str(), 0600), 0);
  ASSERT_EQ(::symlink("/dev/full", dir.file("full.map").c_str()), 0);
  const ToolRun fifo = log2map_few({kIntel, dir.file("p.png")});
  EXPECT_EQ(fifo.status, 1);
  EXPECT_TRUE(contains(fifo.output, "p.png: is a FIFO")) << fifo.output;
  const ToolRun dev = log2map_few({kIntel, dir.file("full.map")});
  EXPECT_EQ(dev.status, 1);
  EXPECT_TRUE(contains(dev.output, "is a character device")) << dev.output;
  struct stat st;
  ASSERT_EQ(::lstat(dir.file("p.png").c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"full.map", "p.png"}));
}

// In a sticky directory, another user's theirs.png cannot be replaced: the
// run is refused before mine.map is touched. Run as an ordinary user (root
// ignores the rule), so only where the test may switch to one.
TEST(Log2Map, AnotherUsersFileInAStickyDirectoryTouchesNoOutput) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to make a file of another user";
  TempDir dir;
  const std::string sticky = maptest::make_sticky_directory(dir);
  ASSERT_FALSE(sticky.empty());
  write_text(dir, "tmp/theirs.png", "root's");
  write_text(dir, "tmp/mine.map", "old map");
  ASSERT_EQ(::chown((sticky + "/mine.map").c_str(), 65534, 65534), 0);
  const std::string cmd = "setpriv --reuid=65534 --regid=65534 --clear-groups " +
                          tooltest::quote(std::string(VASCO_BIN_DIR) + "/log2map") + " --quiet --vasco_num_scans 20 " +
                          tooltest::quote(kIntel) + " " + tooltest::quote(sticky + "/mine.map") + " " +
                          tooltest::quote(sticky + "/theirs.png") + " 2>&1";
  FILE *p = ::popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[512];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  const int st = ::pclose(p);
  if (WIFEXITED(st) && WEXITSTATUS(st) == 127) GTEST_SKIP() << "no setpriv here: " << out;
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 1) << st << " " << out;
  EXPECT_TRUE(contains(out, "sticky")) << out;
  EXPECT_EQ(read_all(sticky + "/mine.map"), "old map");
  EXPECT_EQ(read_all(sticky + "/theirs.png"), "root's");
}

// --max-memory takes whole MiB that fit in 64 bits as bytes; anything else
// is a usage error (17592186044417 MiB wrapped to 1 MiB before).
TEST(Log2Map, MaxMemoryOutOfRangeIsAUsageError) {
  TempDir dir;
  for (const char *bad : {"17592186044417", "18446744073709551616", "-1", "1.5", "", "12abc"}) {
    const ToolRun r = log2map_few({"--max-memory", bad, kIntel, dir.file("a.map")});
    EXPECT_EQ(r.status, 2) << bad << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "--max-memory")) << r.output;
  }
  EXPECT_EQ(log2map_few({"--max-memory", "17592186044415", kIntel, dir.file("a.map")}).status, 0);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"a.map"}));
}

// Runs log2map --json on intel into dir/a.map with standard output as
// `redirect` says; its exit status, and its stderr in *err.
int log2map_json_to(const TempDir &dir, const std::string &redirect, std::string *err) {
  const std::string cmd = tooltest::quote(std::string(VASCO_BIN_DIR) + "/log2map") + " --json --quiet " +
                          tooltest::quote(kIntel) + " " + tooltest::quote(dir.file("a.map")) + " " + redirect +
                          " 2>" + tooltest::quote(dir.file("err.txt"));
  const int st = std::system(cmd.c_str());
  *err = read_all(dir.file("err.txt"));
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

// --json with standard output closed: refused before the maps are made.
TEST(Log2Map, JsonToAClosedStdoutFailsBeforeAnyWork) {
  TempDir dir;
  std::string err;
  EXPECT_EQ(log2map_json_to(dir, ">&-", &err), 1);
  EXPECT_TRUE(contains(err, "standard output is closed")) << err;
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"err.txt"}));
}

// A full stdout is seen only once the maps are written: the message says so.
TEST(Log2Map, JsonToAFullStdoutSaysTheMapsWereWritten) {
  TempDir dir;
  std::string err;
  EXPECT_EQ(log2map_json_to(dir, ">/dev/full", &err), 1);
  EXPECT_TRUE(contains(err, "the maps were written")) << err;
}

}  // namespace

namespace {

const std::string kTestLogs = std::string(VASCO_TEST_DATA_DIR) + "/logs/";

TEST(Log2MapConventions, EveryMessageNamesTheProgramAndABadParameterValueIsAUsageError) {
  TempDir dir;
  const ToolRun none = log2map({});
  EXPECT_EQ(none.status, 2);
  EXPECT_EQ(none.output.rfind("log2map: ", 0), 0u) << none.output;
  const ToolRun bad = log2map({kIntel, dir.file("a.map"), "--vasco_range_max", "abc"});
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_TRUE(contains(bad.output, "log2map: command line: vasco_range_max: 'abc' is not a number")) << bad.output;
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Log2MapConventions, ShortQuietFlagAndHelpShowsEachParametersMeaningAndDefault) {
  TempDir dir;
  const ToolRun q = log2map({"-q", "--backend", "cpu_threads", kIntel, dir.file("a.map")});
  EXPECT_EQ(q.status, 0) << q.output;
  EXPECT_EQ(q.output, "");
  const ToolRun help = log2map({"--help"});
  // The help is the parameters' reference (the README points to it): every
  // key, and two rows written out here by hand.
  EXPECT_TRUE(contains(help.output, "--vasco_p_occ VALUE         evidence of a hit (default 0.55; must be strictly between 0 and 1)"))
      << help.output;
  EXPECT_TRUE(contains(help.output, "number of laser messages used (default -1, all; must be >= 1 (or -1 for all))"))
      << help.output;
  for (const std::string &key : vasco::mapper_param_keys())
    EXPECT_TRUE(contains(help.output, "--" + key + " VALUE")) << key;
}

TEST(Log2MapConventions, OptionsThatDoNothingForTheBackendAreWarnedAboutAndInTheJson) {
  TempDir dir;
  const ToolRun r = log2map({"--json", "-q", "--backend", "cpu_double", "--cuda-mode", "exact", "--threads", "2",
                             "--robot", "r2", kIntel, dir.file("a.map")});
  EXPECT_EQ(r.status, 0) << r.output;
  for (const char *w : {"log2map: warning: --cuda-mode does nothing with --backend cpu_double",
                        "log2map: warning: --threads does nothing with --backend cpu_double",
                        "log2map: warning: --robot does nothing without --param-file"})
    EXPECT_TRUE(contains(r.output, w)) << w << "\n" << r.output;
  EXPECT_TRUE(contains(r.output, "\"warnings\":[\"--cuda-mode does nothing")) << r.output;
  // The effective parameters: the defaults here, one overridden.
  const ToolRun o = log2map({"--json", "-q", "--backend", "cpu_double", "--vasco_downsample", "2", kIntel,
                             dir.file("b.map")}, false);
  EXPECT_TRUE(contains(o.output, "\"parameters\":{\"vasco_resolution\":0.025,")) << o.output;
  EXPECT_TRUE(contains(o.output, "\"vasco_downsample\":2,")) << o.output;
}

TEST(Log2MapConventions, JsonAfterAFailureIsStillOneObjectWithTheError) {
  TempDir dir;
  const ToolRun r = log2map({"--json", kTestLogs + "truncated.log.gz", dir.file("a.map")}, false);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.output, "{\"error\":{\"file\":\"" + kTestLogs +
                          "truncated.log.gz\",\"line\":264,\"message\":\"truncated gzip stream: the compressed data "
                          "ends after 26312 uncompressed bytes, before the end of the stream\",\"kind\":\"bad input\"}}\n");
}

TEST(Log2MapConventions, LenientSummaryEndsItsLinesAndADamagedFileSaysWhyItStops) {
  TempDir dir;
  const ToolRun ok = log2map({"--lenient", "--backend", "cpu_threads", kTestLogs + "mixed_bad.log", dir.file("a.map")});
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_TRUE(contains(ok.output, "(first at line 12)\nlog2map: grid ")) << ok.output;
  const ToolRun gz = log2map({"--lenient", kTestLogs + "truncated.log.gz", dir.file("b.map")});
  EXPECT_EQ(gz.status, 1);
  EXPECT_TRUE(contains(gz.output, "truncated gzip stream")) << gz.output;
  EXPECT_TRUE(contains(gz.output, "--lenient skips bad lines, not a damaged file")) << gz.output;
  EXPECT_TRUE(dir.entries() == std::vector<std::string>{"a.map"});
}

}  // namespace

namespace {

// "-": the log from standard input, a CARMEN map to standard output, the same
// bytes in the GRIDMAP as a file written the usual way.
TEST(Log2MapConventions, DashIsStandardInputAndOutput) {
  TempDir dir;
  const std::string piped = dir.file("piped.map");
  ASSERT_EQ(tooltest::run_tool_piped(kIntel, "log2map", {"-q", "--backend", "cpu_threads", "-", "-"}, piped), 0)
      << maptest::read_bytes(piped + ".err");
  ASSERT_EQ(log2map({"-q", "--backend", "cpu_threads", kIntel, dir.file("file.map")}).status, 0);
  const carmen::MapFile a = carmen::read_map_file(piped), b = carmen::read_map_file(dir.file("file.map"));
  ASSERT_TRUE(a.gridmap && b.gridmap);
  EXPECT_EQ(a.gridmap->cells, b.gridmap->cells);
  EXPECT_EQ(log2map({kIntel, "-", "-"}).status, 2);            // standard output twice
  EXPECT_EQ(log2map({"--json", kIntel, "-"}).status, 2);       // --json wants it too
}

}  // namespace

namespace {

// --json is UTF-8 whatever the file names: a byte that is not (a Latin-1
// name) comes out as \u00XX.
TEST(Log2MapConventions, JsonEscapesBytesThatAreNotUtf8) {
  TempDir dir;
  const ToolRun r = log2map({"--json", dir.file("caf\xe9.log"), dir.file("a.map")}, false);
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.output, "caf\\u00e9.log")) << r.output;
  EXPECT_FALSE(contains(r.output, "caf\xe9")) << r.output;
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
