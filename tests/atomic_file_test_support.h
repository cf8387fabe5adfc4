// What the atomic output tests share: whole-file I/O that does not use the
// library under test, a check that an action is refused naming the file, and
// an output of a transaction written in one call.
#ifndef VASCO_TESTS_ATOMIC_FILE_TEST_SUPPORT_H
#define VASCO_TESTS_ATOMIC_FILE_TEST_SUPPORT_H

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"
#include "map_test_support.h"

namespace atomictest {

using maptest::read_bytes;
using maptest::TempDir;
using maptest::write_bytes;

inline std::string read_text(const std::string &path) { return read_bytes(path); }

inline void write_text(const std::string &path, const std::string &text) {
  FILE *f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr) << path;
  std::fputs(text.c_str(), f);
  std::fclose(f);
}

// Runs `action`, which must throw a carmen::FileError naming `file`, of code
// I/O, whose message holds `part`.
template <class Action>
void expect_refused(Action action, const std::string &file, const std::string &part) {
  try {
    action();
    ADD_FAILURE() << file << ": not refused";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.code(), carmen::ErrorCode::Io) << e.what();
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

// Writes `text` into a new output of `tx`.
inline void add_output(carmen::OutputTransaction &tx, const std::string &path, const std::string &text) {
  FILE *f = tx.add(path).take_stdio();
  std::fputs(text.c_str(), f);
  std::fclose(f);
}

}  // namespace atomictest

#endif  // VASCO_TESTS_ATOMIC_FILE_TEST_SUPPORT_H
