// Tests of the log reader's memory budget (LogReaderOptions::memory_budget):
// counted while reading, refused at the message that passes it, before the
// rest of the log is read.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "carmen_compat/error.h"
#include "carmen_compat/log_reader.h"

namespace {

using carmen::ErrorCode;
using carmen::FileError;
using carmen::LogMessage;
using carmen::LogReader;
using carmen::LogReaderOptions;
using carmen::MessageType;

// A temporary file holding `text`, removed at the end.
class TempLog {
 public:
  explicit TempLog(const std::string &text) {
    char tmpl[] = "/tmp/log_reader_budget_test_XXXXXX";
    const int fd = mkstemp(tmpl);
    path_ = tmpl;
    std::FILE *f = fdopen(fd, "wb");
    std::fwrite(text.data(), 1, text.size(), f);
    std::fclose(f);
  }
  ~TempLog() { std::remove(path_.c_str()); }
  const std::string &path() const { return path_; }

 private:
  std::string path_;
};

// "FLASER n r... 0 0 0 0 0 0 1 host 2" with n ranges of 1.5.
std::string flaser_line(int beams) {
  std::string s = "FLASER " + std::to_string(beams);
  for (int i = 0; i < beams; ++i) s += " 1.5";
  return s + " 0 0 0 0 0 0 1 host 2\n";
}

// Reads until the reader throws; returns the error (fails the test when none comes).
FileError read_until_error(LogReader &reader) {
  LogMessage m;
  try {
    while (reader.next(m)) {
    }
  } catch (const FileError &e) {
    return e;
  }
  ADD_FAILURE() << "the budget was never passed";
  return FileError(reader.path(), "none");
}

TEST(LogReaderBudget, ManyLongScansStopAtTheScanThatPassesTheBudget) {
  std::string text;
  for (int i = 0; i < 40; ++i) text += flaser_line(100000);
  TempLog log(text);
  LogReaderOptions opt;
  opt.memory_budget = 4000000;
  opt.budget_option = "--max-memory";
  LogReader reader(log.path(), opt);
  const FileError e = read_until_error(reader);
  // Each scan keeps 100000 floats and 64 bytes: 10 * 400064 > 4e6 >= 9 * 400064.
  EXPECT_EQ(e.line(), 10);
  EXPECT_EQ(e.code(), ErrorCode::OutOfMemory);
  EXPECT_EQ(e.file(), log.path());
  const std::string what = e.what();
  EXPECT_NE(what.find("memory budget of 4000000 bytes"), std::string::npos) << what;
  EXPECT_NE(what.find("--max-memory"), std::string::npos) << what;
  // Refused while reading: most of the log was never read.
  EXPECT_LT(reader.stats().bytes, text.size() / 2);
}

TEST(LogReaderBudget, ManyParamLinesPassIt) {
  std::string text;
  uint64_t kept = 0;
  long passed_at = 0;
  for (int i = 1; i <= 50000; ++i) {
    const std::string name = "robot_key_" + std::to_string(i), value = std::to_string(i * 7);
    text += "PARAM " + name + " " + value + " nohost 0\n";
    kept += 64 + name.size() + value.size();
    if (passed_at == 0 && kept > 1000000) passed_at = i;
  }
  TempLog log(text);
  LogReaderOptions opt;
  opt.memory_budget = 1000000;
  LogReader reader(log.path(), opt);
  const FileError e = read_until_error(reader);
  EXPECT_EQ(e.line(), passed_at);
  EXPECT_EQ(e.code(), ErrorCode::OutOfMemory);
}

TEST(LogReaderBudget, OnlyTheTypesTheCallerKeepsCount) {
  std::string text;
  for (int i = 0; i < 20; ++i) text += "RAWLASER1 0 -1.57 3.14 0.01 80 0.01 0 3 1 2 3 0 1 host 2\n";
  text += flaser_line(3);
  TempLog log(text);
  LogReaderOptions opt;
  opt.memory_budget = 100;  // one FLASER of 3 beams: 76 bytes; 20 RAWLASER1s would be 1520
  opt.budget_types = carmen::message_type_bit(MessageType::FLASER);
  LogReader reader(log.path(), opt);
  LogMessage m;
  int n = 0;
  while (reader.next(m)) ++n;
  EXPECT_EQ(n, 21);
  EXPECT_EQ(reader.stats().kept_bytes, 64u + 3 * 4);
}

TEST(LogReaderBudget, ZeroMeansNoLimitAndStillCounts) {
  std::string text;
  for (int i = 0; i < 5; ++i) text += flaser_line(1000);
  text += "PARAM a bc\n";
  TempLog log(text);
  LogReader reader(log.path());
  LogMessage m;
  while (reader.next(m)) {
  }
  EXPECT_EQ(reader.stats().kept_bytes, 5 * (64u + 4000) + 64 + 3);
}

TEST(LogReaderBudget, LenientModeRefusesToo) {
  std::string text = flaser_line(1000) + flaser_line(1000);
  TempLog log(text);
  LogReaderOptions opt;
  opt.strict = false;
  opt.memory_budget = 5000;
  LogReader reader(log.path(), opt);
  EXPECT_EQ(read_until_error(reader).line(), 2);
}

}  // namespace
