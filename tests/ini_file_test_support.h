// What the carmen.ini tests share: the test files, the text of the FileError
// a call throws, and a parsed file's values, lines and warnings.
#ifndef VASCO_TESTS_INI_FILE_TEST_SUPPORT_H
#define VASCO_TESTS_INI_FILE_TEST_SUPPORT_H

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "carmen_compat/ini_file.h"

namespace initest {

using carmen::FileError;
using carmen::ParamFile;
using carmen::ParamValue;

inline const std::string kDir = std::string(VASCO_TEST_DATA_DIR) + "/ini/";

inline std::string path(const std::string &name) { return kDir + name; }

// what() of the FileError that `f` throws ("" and a failure when none).
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const FileError &e) {
    return e.what();
  }
  ADD_FAILURE() << "no FileError was thrown";
  return "";
}

inline ::testing::AssertionResult contains(const std::string &text, const std::string &part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

// The value of `name`, or a marker when it is not defined.
inline std::string value_of(const ParamFile &pf, const std::string &name) {
  const auto pv = pf.find(name);
  return pv ? pv->value : "<undefined>";
}

inline long line_of(const ParamFile &pf, const std::string &name) {
  const auto pv = pf.find(name);
  return pv ? pv->line : -1;
}

inline std::vector<std::string> warning_texts(const ParamFile &pf) {
  std::vector<std::string> out;
  for (const auto &w : pf.warnings()) out.push_back(w.str());
  return out;
}

}  // namespace initest

#endif  // VASCO_TESTS_INI_FILE_TEST_SUPPORT_H
