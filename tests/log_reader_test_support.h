// What the log reader tests share: the logs they read, whole-file I/O that
// does not use the reader, a reader that expects a FileError naming file and
// line, and an independent tokenizer (for comparisons with strtod).
#ifndef VASCO_TESTS_LOG_READER_TEST_SUPPORT_H
#define VASCO_TESTS_LOG_READER_TEST_SUPPORT_H

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <zlib.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "carmen_compat/log_reader.h"

namespace logtest {

using carmen::BadLine;
using carmen::FileError;
using carmen::LineKind;
using carmen::LogMessage;
using carmen::LogReader;
using carmen::LogReaderOptions;
using carmen::LogStats;
using carmen::MessageType;

constexpr double kPi = 3.14159265358979323846;

inline std::string bad_log(const std::string &name) {
  return std::string(VASCO_TEST_DATA_DIR) + "/logs/" + name;
}
inline std::string bundled_log(const std::string &name) { return std::string(VASCO_LOGS_DIR) + "/" + name; }
inline std::string shared_data() { return std::string(VASCO_SHARED_DIR) + "/data"; }

inline bool is_dir(const std::string &p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

inline std::string read_file(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}
inline void write_file(const std::string &path, const std::string &data) {
  std::ofstream out(path, std::ios::binary);
  out << data;
}
inline std::string gunzip(const std::string &path) {
  gzFile in = gzopen(path.c_str(), "rb");
  std::string out;
  if (!in) return out;
  char buf[1 << 16];
  int n;
  while ((n = gzread(in, buf, sizeof buf)) > 0) out.append(buf, static_cast<size_t>(n));
  gzclose(in);
  return out;
}

// Reads the whole log; returns the messages.
inline std::vector<LogMessage> read_all(const std::string &path, LogReaderOptions opt = {},
                                        LogStats *stats = nullptr) {
  return carmen::read_log(path, opt, stats);
}

// Expects a FileError whose what() starts with "<file>:<line>:" (line 0: no
// line) and contains `needle`; returns the error for more checks.
inline void expect_file_error(const std::string &path, long line, const std::string &needle,
                              LogReaderOptions opt = {}) {
  SCOPED_TRACE(path);
  try {
    read_all(path, opt);
    ADD_FAILURE() << "no FileError for " << path;
  } catch (const FileError &e) {
    const std::string what = e.what();
    const std::string prefix = line > 0 ? path + ":" + std::to_string(line) + ": " : path + ": ";
    EXPECT_EQ(what.rfind(prefix, 0), 0u) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), line) << what;
  }
}

// A line split at blanks, its fields read one by one with strtod and strtol:
// an independent parse to compare the reader's fields with.
struct Tokens {
  std::vector<std::string> t;
  size_t i = 0;
  double d() { return std::strtod(t.at(i++).c_str(), nullptr); }
  long l() { return std::strtol(t.at(i++).c_str(), nullptr, 10); }
  std::string s() { return t.at(i++); }
};

inline Tokens tokenize(const std::string &line) {
  Tokens k;
  size_t p = 0;
  while (p < line.size()) {
    while (p < line.size() && (line[p] == ' ' || line[p] == '\t' || line[p] == '\r')) ++p;
    size_t q = p;
    while (q < line.size() && line[q] != ' ' && line[q] != '\t' && line[q] != '\r') ++q;
    if (q > p) k.t.push_back(line.substr(p, q - p));
    p = q;
  }
  return k;
}

}  // namespace logtest

#endif  // VASCO_TESTS_LOG_READER_TEST_SUPPORT_H
