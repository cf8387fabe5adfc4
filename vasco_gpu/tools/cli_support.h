// cli_support.h — what the command-line tools (log2map, mapconvert, mapdiff)
// share: timing, JSON strings, exit statuses by error code, and the checks
// made on output paths and options before any work starts.
#ifndef VASCO_GPU_TOOLS_CLI_SUPPORT_H
#define VASCO_GPU_TOOLS_CLI_SUPPORT_H

#include <chrono>
#include <cstdint>
#include <exception>
#include <string>
#include <vector>

namespace cli {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0);

// `text` as a JSON string, quotes included (control characters as \uXXXX).
std::string json_string(const std::string &text);

// The exit status of a run that ended with `e`: `usage` for a
// carmen::Error of code Usage, `other` for any other failure.
int exit_status(const std::exception &e, int usage = 2, int other = 1);

// Refuses, before any work, outputs that cannot or must not be written:
// each must pass carmen::check_replaceable (carmen::FileError, code I/O), none
// may be one of `inputs` (by device and inode: a log, an ini, a map read) and
// none may be named twice (carmen::Error, code Usage). `outputs` lists every
// file a run creates (a .pgm's .yaml included).
void check_outputs(const std::vector<std::string> &inputs, const std::vector<std::string> &outputs);

// A whole number of MiB, as bytes. Throws carmen::Error(Usage) naming
// `option` for anything but digits, or a value whose bytes overflow 64 bits.
uint64_t parse_mebibytes(const std::string &text, const std::string &option);

// Throws carmen::Error(Io) when standard output is closed or read-only, so
// that `--json` fails before the maps are made rather than after.
void check_stdout_writable(const std::string &why);

}  // namespace cli

#endif  // VASCO_GPU_TOOLS_CLI_SUPPORT_H
