// Helpers shared by the tests of pose files (pose_file_test.cc) and of their
// matching to scans (pose_match_test.cc).
#ifndef VASCO_TESTS_POSE_TEST_SUPPORT_H
#define VASCO_TESTS_POSE_TEST_SUPPORT_H

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>

#include "carmen_compat/error.h"

namespace pose_test {

constexpr double kPi = 3.14159265358979323846;

inline void write_file(const std::string &path, const std::string &text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// "%.17g": enough digits for any double to read back as itself.
inline std::string g17(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The what() of the carmen::Error that f throws, checked to have `code`;
// "" (and a failure) when it throws none.
inline std::string error_of(const std::function<void()> &f, carmen::ErrorCode code) {
  try {
    f();
  } catch (const carmen::Error &e) {
    EXPECT_EQ(carmen::error_code_name(e.code()), std::string(carmen::error_code_name(code))) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error thrown";
  return "";
}

}  // namespace pose_test

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "'" << (text) << "' lacks '" << (part) << "'"

#endif  // VASCO_TESTS_POSE_TEST_SUPPORT_H
