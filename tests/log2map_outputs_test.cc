// The log2map tool, run as a program: its output transaction end to end
// (outputs that are inputs, special files, sticky directories, locks) and
// what --json and --max-memory do to it.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "log2map_test_support.h"
#include "map_test_support.h"
#include "sticky_dir.h"

namespace {

using namespace log2maptest;

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
