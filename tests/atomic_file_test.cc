// carmen_compat/atomic_file.h: temp file + rename.
#include "carmen_compat/atomic_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <stdexcept>

#include "carmen_compat/error.h"
#include "map_test_support.h"

namespace {

using maptest::read_bytes;
using maptest::TempDir;
using maptest::write_bytes;

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

TEST(MapAtomicOutput, CommitWithoutDataFails) {
  TempDir dir;
  carmen::AtomicOutput out(dir.file("never.txt"));
  try {
    out.commit();
    ADD_FAILURE() << "commit succeeded without a file";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), dir.file("never.txt"));
    EXPECT_NE(std::string(e.what()).find("nothing was written"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(dir.entries().empty());
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
