// What the log2map tests share: the tool run as a program, the bundled intel
// log and small text files written for a run.
#ifndef VASCO_TESTS_LOG2MAP_TEST_SUPPORT_H
#define VASCO_TESTS_LOG2MAP_TEST_SUPPORT_H

#include <fstream>
#include <string>
#include <vector>

#include "map_test_support.h"
#include "tool_support.h"

namespace log2maptest {

using maptest::TempDir;

using tooltest::contains;
using tooltest::ToolRun;

inline ToolRun log2map(const std::vector<std::string> &args, bool with_stderr = true) {
  return tooltest::run_tool("log2map", args, with_stderr);
}

const std::string kIntel = std::string(VASCO_LOGS_DIR) + "/intel.gfs.log.gz";

inline std::string write_text(const TempDir &dir, const std::string &name, const std::string &text) {
  const std::string path = dir.file(name);
  std::ofstream(path) << text;
  return path;
}

}  // namespace log2maptest

#endif  // VASCO_TESTS_LOG2MAP_TEST_SUPPORT_H
