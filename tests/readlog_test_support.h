// What the readlog tests share: the test logs and a line as a writable C
// string (CARMEN's converters take char *).
#ifndef VASCO_TESTS_READLOG_TEST_SUPPORT_H
#define VASCO_TESTS_READLOG_TEST_SUPPORT_H

#include <string>
#include <vector>

namespace readlogtest {

inline std::string bad_log(const std::string &name) {
  return std::string(VASCO_TEST_DATA_DIR) + "/logs/" + name;
}

inline std::vector<char> buffer(const std::string &s) {
  std::vector<char> v(s.begin(), s.end());
  v.push_back('\0');
  return v;
}

}  // namespace readlogtest

#endif  // VASCO_TESTS_READLOG_TEST_SUPPORT_H
