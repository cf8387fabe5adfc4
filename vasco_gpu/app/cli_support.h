// cli_support.h — what the command-line tools (log2map, mapconvert, mapdiff)
// share: timing, JSON strings, exit statuses by error code, and the checks
// made on output paths and options before any work starts.
#ifndef VASCO_GPU_TOOLS_CLI_SUPPORT_H
#define VASCO_GPU_TOOLS_CLI_SUPPORT_H

#include <chrono>
#include <cstdint>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "carmen_compat/atomic_file.h"

namespace cli {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0);

// `text` as a JSON string, quotes included (control characters as \uXXXX).
std::string json_string(const std::string &text);

// The exit status of a run that ended with `e`: `usage` for a
// carmen::Error of code Usage, `other` for any other failure.
int exit_status(const std::exception &e, int usage = 2, int other = 1);


// A whole number of MiB, as bytes. Throws carmen::Error(Usage) naming
// `option` for anything but digits, or a value whose bytes overflow 64 bits.
uint64_t parse_mebibytes(const std::string &text, const std::string &option);

// "-" names standard input (an input) or standard output (an output), as
// Unix tools do. An input "-" is read as /dev/stdin (a pipe or a file: the
// readers read it front to back). An output "-" is a CARMEN map (.map) on
// standard output.
constexpr const char *kStdio = "-";
std::string input_path(const std::string &arg);

// An output "-": the file is made in a private temporary directory (by the
// same writers and transaction as any output), then copied to standard
// output once whole, so a failed run writes nothing there; the directory is
// removed whatever happens.
class StdoutFile {
 public:
  explicit StdoutFile(const std::string &extension);  // ".map"
  ~StdoutFile();
  StdoutFile(const StdoutFile &) = delete;
  StdoutFile &operator=(const StdoutFile &) = delete;
  const std::string &path() const { return path_; }
  // Copies the finished file to standard output; carmen::Error(Io) when
  // standard output refuses it.
  void send() const;

 private:
  std::string dir_, path_;
  // Both go if a signal kills the process while the map is made or sent
  // (remove_temporaries_on_signals): the directory after its file.
  std::unique_ptr<carmen::TemporaryOnSignal> dir_on_signal_, path_on_signal_;
};

// Throws carmen::Error(Io) when standard output is closed or read-only, so
// that `--json` fails before the maps are made rather than after.
void check_stdout_writable(const std::string &why);

}  // namespace cli

#endif  // VASCO_GPU_TOOLS_CLI_SUPPORT_H
