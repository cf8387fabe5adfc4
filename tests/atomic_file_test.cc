// carmen_compat/atomic_file.h: temp file + rename, one output at a time;
// what a target must be to be replaced. Several outputs committed together:
// atomic_file_transaction_test.cc.
#include "carmen_compat/atomic_file.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <fcntl.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "carmen_compat/error.h"
#include "atomic_file_test_support.h"
#include "sticky_dir.h"

namespace {

using namespace atomictest;

TEST(MapAtomicOutput, TempFileIsHiddenBesideTheTarget) {
  TempDir dir;
  carmen::AtomicOutput out(dir.file("map.pgm"));
  const std::string temp = out.temp_path();
  const std::string prefix = dir.path() + "/.map.pgm.tmp." + std::to_string(::getpid()) + ".";
  EXPECT_EQ(temp.rfind(prefix, 0), 0u) << temp;
  EXPECT_EQ(out.final_path(), dir.file("map.pgm"));
  carmen::AtomicOutput other(dir.file("map.pgm"));
  EXPECT_NE(other.temp_path(), temp);      // unique within a process
  carmen::AtomicOutput bare("plain.txt");  // no directory part: the current one
  EXPECT_EQ(bare.temp_path().rfind(".plain.txt.tmp.", 0), 0u) << bare.temp_path();
}

TEST(MapAtomicOutput, CommitMovesTheFileIntoPlace) {
  TempDir dir;
  const std::string path = dir.file("out.txt");
  write_bytes(path, "old");
  {
    carmen::AtomicOutput out(path);
    write_text(out.temp_path(), "new contents");
    EXPECT_EQ(read_bytes(path), "old");  // untouched until commit
    out.commit();
    EXPECT_TRUE(out.committed());
    EXPECT_THROW(out.commit(), std::logic_error);
  }
  EXPECT_EQ(read_bytes(path), "new contents");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.txt"});
}

TEST(MapAtomicOutput, DurableCommitWorksToo) {
  TempDir dir;
  carmen::AtomicOutput out(dir.file("d.txt"));
  write_text(out.temp_path(), "x");
  out.commit(true);
  EXPECT_EQ(read_bytes(dir.file("d.txt")), "x");
}

TEST(MapAtomicOutput, AThrowingWriterLeavesNoFile) {
  TempDir dir;
  const std::string path = dir.file("half.map");
  auto writer = [&] {
    carmen::AtomicOutput out(path);
    write_text(out.temp_path(), "half of a fi");
    throw std::runtime_error("disk on fire");
  };
  EXPECT_THROW(writer(), std::runtime_error);
  EXPECT_TRUE(dir.entries().empty());  // neither the target nor the temp file

  // With an old file in place, the old file survives.
  write_bytes(path, "complete old file");
  EXPECT_THROW(writer(), std::runtime_error);
  EXPECT_EQ(read_bytes(path), "complete old file");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"half.map"});
}

TEST(MapAtomicOutput, AbandonRemovesTheTempFile) {
  TempDir dir;
  carmen::AtomicOutput out(dir.file("a"));
  write_text(out.temp_path(), "x");
  ASSERT_EQ(dir.entries().size(), 1u);
  out.abandon();
  EXPECT_TRUE(dir.entries().empty());
}

TEST(MapAtomicOutput, CommitFailsWhenTheTemporaryVanished) {
  TempDir dir;
  carmen::AtomicOutput out(dir.file("never.txt"));
  ::unlink(out.temp_path().c_str());
  try {
    out.commit();
    ADD_FAILURE() << "commit succeeded without a file";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), dir.file("never.txt"));
    EXPECT_NE(std::string(e.what()).find("nothing was written"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(dir.entries().empty());
}

// Another user who can write the directory plants a symlink where the
// temporary would go: it is never opened (O_EXCL | O_NOFOLLOW), its target is
// untouched, another name is drawn.
TEST(MapAtomicOutput, APlantedSymlinkIsNeverFollowed) {
  TempDir dir;
  const std::string victim = dir.file("victim.txt");
  write_text(victim, "precious");
  const std::string planted = dir.file(".out.map.tmp." + std::to_string(::getpid()) + ".planted");
  ASSERT_EQ(::symlink(victim.c_str(), planted.c_str()), 0);
  int calls = 0;
  carmen::AtomicOutput::set_name_source_for_testing([&] { return ++calls == 1 ? "planted" : "fresh"; });
  {
    carmen::AtomicOutput out(dir.file("out.map"));
    carmen::AtomicOutput::set_name_source_for_testing(nullptr);
    EXPECT_NE(out.temp_path().find(".fresh"), std::string::npos) << out.temp_path();
    FILE *f = out.take_stdio();
    std::fputs("new map", f);
    std::fclose(f);
    out.commit();
  }
  carmen::AtomicOutput::set_name_source_for_testing(nullptr);
  EXPECT_EQ(read_text(victim), "precious");
  EXPECT_EQ(read_text(dir.file("out.map")), "new map");
}

TEST(MapAtomicOutput, TheTemporaryIsAPrivateRegularFileModeFromTheUmask) {
  TempDir dir;
  const mode_t old = ::umask(027);
  carmen::AtomicOutput out(dir.file("m.map"));
  ::umask(old);
  struct stat st;
  ASSERT_EQ(::lstat(out.temp_path().c_str(), &st), 0);
  EXPECT_TRUE(S_ISREG(st.st_mode));
  EXPECT_EQ(st.st_mode & 0777, 0640u);
}

// SIGTERM while an output is being written: the temporary goes, the process
// dies of the signal.
TEST(MapAtomicOutput, SignalsRemoveTheTemporaries) {
  TempDir dir;
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    carmen::remove_temporaries_on_signals();
    carmen::AtomicOutput a(dir.file("a.map")), b(dir.file("b.png"));
    ::raise(SIGTERM);
    ::_exit(3);  // not reached
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
  EXPECT_TRUE(dir.entries().empty());
}

// A directory of our own (log2map's for the output '-') registered with its
// file and an output being written in it: a signal removes all three, the
// directory after what is in it, whatever the order they were registered in.
TEST(MapAtomicOutput, SignalsRemoveOurDirectoriesToo) {
  TempDir dir;
  const std::string own = dir.file("own");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    carmen::remove_temporaries_on_signals();
    if (::mkdir(own.c_str(), 0700) != 0) ::_exit(4);
    carmen::TemporaryOnSignal d(own), f(own + "/stdout.map");
    write_text(own + "/stdout.map", "done map");
    carmen::AtomicOutput late(own + "/more.map");
    ::raise(SIGTERM);
    ::_exit(3);  // not reached
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
  EXPECT_TRUE(dir.entries().empty()) << (dir.entries().empty() ? "" : dir.entries()[0]);
}

// A directory is refused when the output is made (before any temporary
// appears), and again at commit should one have taken the target's place.
TEST(MapAtomicOutput, ADirectoryTargetIsRefused) {
  TempDir dir;
  const std::string target = dir.file("sub");
  ASSERT_TRUE(std::filesystem::create_directory(target));
  expect_refused([&] { carmen::AtomicOutput out(target); }, target, "is a directory");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"sub"});

  carmen::AtomicOutput late(dir.file("late"));
  ASSERT_TRUE(std::filesystem::create_directory(dir.file("late")));
  write_bytes(dir.file("late") + "/keep", "k");
  expect_refused([&] { late.commit(); }, dir.file("late"), "is a directory");
  EXPECT_FALSE(late.committed());
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"late", "sub"}));
}

TEST(MapAtomicOutput, RejectsPathsWithoutAFileName) {
  EXPECT_THROW(carmen::AtomicOutput(""), carmen::FileError);
  EXPECT_THROW(carmen::AtomicOutput("some/dir/"), carmen::FileError);
}

TEST(MapAtomicWrite, WritesAndReportsErrors) {
  TempDir dir;
  carmen::write_file_atomically(dir.file("w.bin"), std::string("a\0b", 3));
  EXPECT_EQ(read_bytes(dir.file("w.bin")), std::string("a\0b", 3));
  try {
    carmen::write_file_atomically(dir.file("missing/w.bin"), "x");
    ADD_FAILURE() << "wrote into a missing directory";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), dir.file("missing/w.bin"));
  }
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"w.bin"});
}

// A device, a FIFO, a link to a device: never renamed over, and no
// temporary is made beside them.
TEST(MapCheckReplaceable, SpecialFilesAreRefused) {
  TempDir dir;
  ASSERT_EQ(::mkfifo(dir.file("pipe").c_str(), 0600), 0);
  ASSERT_EQ(::symlink("/dev/null", dir.file("null.png").c_str()), 0);
  expect_refused([&] { carmen::AtomicOutput out(dir.file("pipe")); }, dir.file("pipe"), "is a FIFO");
  expect_refused([&] { carmen::check_replaceable(dir.file("null.png")); }, dir.file("null.png"),
                 "is a character device");
  expect_refused([&] { carmen::AtomicOutput out("/dev/full"); }, "/dev/full", "is a character device");
  struct stat st;
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"null.png", "pipe"}));
  carmen::check_replaceable(dir.file("new.map"));  // a new file, and
  write_text(dir.file("old.map"), "x");
  carmen::check_replaceable(dir.file("old.map"));  // an old regular one, pass
  expect_refused([&] { carmen::check_replaceable(dir.file("none/x.map")); }, dir.file("none/x.map"),
                 "does not exist");
}

// Mount points listed by /proc/self/mountinfo (read here with no code of the
// library): a file bind-mounted there cannot be replaced (EBUSY).
std::string a_mounted_regular_file() {
  std::ifstream mounts("/proc/self/mountinfo");
  std::string line;
  while (std::getline(mounts, line)) {
    std::istringstream fields(line);
    std::string skip, point;
    for (int i = 0; i < 4; ++i) fields >> skip;
    fields >> point;
    struct stat st;
    if (point.find('\\') == std::string::npos && ::lstat(point.c_str(), &st) == 0 && S_ISREG(st.st_mode)) return point;
  }
  return std::string();
}

TEST(MapCheckReplaceable, AMountPointIsRefused) {
  const std::string mounted = a_mounted_regular_file();
  if (!mounted.empty())
    expect_refused([&] { carmen::check_replaceable(mounted); }, mounted, "is a mount point");
  // A file bind-mounted over an output, where this process may mount: the
  // commit is refused before a.map appears.
  TempDir dir;
  write_text(dir.file("src"), "source");
  write_text(dir.file("bound.png"), "bound");
  if (::mount(dir.file("src").c_str(), dir.file("bound.png").c_str(), nullptr, MS_BIND, nullptr) != 0) {
    if (mounted.empty()) GTEST_SKIP() << "no bind-mounted file here, and mount: " << std::strerror(errno);
    return;
  }
  {
    carmen::OutputTransaction tx;
    add_output(tx, dir.file("a.map"), "new");
    expect_refused([&] { add_output(tx, dir.file("bound.png"), "new"); }, dir.file("bound.png"),
                   "is a mount point");
    tx.commit();  // what was added before the refusal still commits
  }
  ::umount2(dir.file("bound.png").c_str(), MNT_DETACH);
  EXPECT_EQ(read_text(dir.file("bound.png")), "bound");
}

// In a sticky directory another user's file cannot be replaced by us (the
// rename would fail EPERM); our own can. Root ignores the rule, so the check
// runs in a child that gives up root.
TEST(MapCheckReplaceable, AnotherUsersFileInAStickyDirectoryIsRefused) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to make a file of another user";
  TempDir dir;
  const std::string sticky = maptest::make_sticky_directory(dir);
  ASSERT_FALSE(sticky.empty());
  write_text(sticky + "/theirs.png", "root's");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    if (::setuid(65534) != 0) ::_exit(3);
    int status = 0;
    try {
      carmen::check_replaceable(sticky + "/theirs.png");
      status = 1;
    } catch (const carmen::FileError &e) {
      if (std::string(e.what()).find("sticky") == std::string::npos) status = 2;
    }
    try {
      write_text(sticky + "/mine.map", "mine");
      carmen::check_replaceable(sticky + "/mine.map");
    } catch (...) {
      status = 4;
    }
    ::_exit(status);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  EXPECT_EQ(read_text(sticky + "/theirs.png"), "root's");
}

TEST(MapSameTarget, ByDirectoryAndNameOrByInode) {
  TempDir dir;
  write_text(dir.file("log"), "x");
  ASSERT_EQ(::link(dir.file("log").c_str(), dir.file("hard").c_str()), 0);
  ASSERT_EQ(::symlink(dir.path().c_str(), dir.file("alias").c_str()), 0);
  EXPECT_TRUE(carmen::same_target(dir.file("d.map"), dir.path() + "/./d.map"));  // new, one directory
  EXPECT_TRUE(carmen::same_target(dir.file("d.map"), dir.file("alias/d.map")));
  EXPECT_TRUE(carmen::same_target(dir.file("log"), dir.file("hard")));  // one inode
  EXPECT_FALSE(carmen::same_target(dir.file("d.map"), dir.file("e.map")));
  EXPECT_FALSE(carmen::same_target(dir.file("log"), dir.file("none/log")));
}

}  // namespace
