// Running the project's command-line tools from tests.
#ifndef VASCO_TESTS_TOOL_SUPPORT_H
#define VASCO_TESTS_TOOL_SUPPORT_H

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace tooltest {

struct ToolRun {
  int status = -1;     // exit code (-1: did not exit normally)
  std::string output;  // stdout, and stderr too unless discarded
};

inline std::string quote(const std::string &s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs <build>/bin/TOOL with `args` (shell-quoted); a run that hangs is
// stopped after two minutes (status 124).
inline ToolRun run_tool(const std::string &tool, const std::vector<std::string> &args,
                        bool with_stderr = true) {
  std::string cmd = "timeout -k 5 120 " + quote(std::string(VASCO_BIN_DIR) + "/" + tool);
  for (const std::string &a : args) cmd += " " + quote(a);
  cmd += with_stderr ? " 2>&1" : " 2>/dev/null";
  ToolRun r;
  FILE *p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int st = ::pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

// Runs `stdin_file | <build>/bin/TOOL args > stdout_file` (stderr to
// stdout_file's ".err"), for the tools' "-" (standard input and output).
inline int run_tool_piped(const std::string &stdin_file, const std::string &tool, const std::vector<std::string> &args,
                          const std::string &stdout_file) {
  std::string cmd = "timeout -k 5 120 " + quote(std::string(VASCO_BIN_DIR) + "/" + tool);
  for (const std::string &a : args) cmd += " " + quote(a);
  cmd += " < " + quote(stdin_file) + " > " + quote(stdout_file) + " 2> " + quote(stdout_file + ".err");
  const int st = std::system(cmd.c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

inline bool contains(const std::string &s, const std::string &part) {
  return s.find(part) != std::string::npos;
}

}  // namespace tooltest

#endif  // VASCO_TESTS_TOOL_SUPPORT_H
