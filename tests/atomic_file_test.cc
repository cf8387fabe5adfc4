// carmen_compat/atomic_file.h: temp file + rename.
#include "carmen_compat/atomic_file.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "carmen_compat/error.h"
#include "map_test_support.h"

namespace {

using maptest::read_bytes;
using maptest::TempDir;
using maptest::write_bytes;

std::string read_text(const std::string &path) { return read_bytes(path); }

void write_text(const std::string &path, const std::string &text) {
  FILE *f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr) << path;
  std::fputs(text.c_str(), f);
  std::fclose(f);
}

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

TEST(MapAtomicOutput, RenameFailureIsReportedAndCleanedUp) {
  TempDir dir;
  // The target is a non-empty directory: rename() cannot replace it.
  const std::string target = dir.file("sub");
  ASSERT_TRUE(std::filesystem::create_directory(target));
  write_bytes(target + "/keep", "k");
  carmen::AtomicOutput out(target);
  write_text(out.temp_path(), "x");
  EXPECT_THROW(out.commit(), carmen::FileError);
  EXPECT_FALSE(out.committed());
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"sub"});
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

}  // namespace
