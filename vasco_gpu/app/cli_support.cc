// The tools' shared helpers (cli_support.h).
#include "cli_support.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"
#include "carmen_compat/ini_file.h"

namespace cli {

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

namespace {

// The length of the well-formed UTF-8 sequence at text[i] (RFC 3629: no
// overlong forms, no surrogates, nothing past U+10FFFF), 0 if there is none.
size_t utf8_length(const std::string &text, size_t i) {
  const auto at = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = at(i);
  size_t n;
  unsigned lo = 0x80, hi = 0xbf;  // the range of the second byte
  if (c < 0x80) return 1;
  if (c >= 0xc2 && c <= 0xdf) {
    n = 2;
  } else if (c >= 0xe0 && c <= 0xef) {
    n = 3;
    if (c == 0xe0) lo = 0xa0;
    if (c == 0xed) hi = 0x9f;
  } else if (c >= 0xf0 && c <= 0xf4) {
    n = 4;
    if (c == 0xf0) lo = 0x90;
    if (c == 0xf4) hi = 0x8f;
  } else {
    return 0;
  }
  if (i + n > text.size() || at(i + 1) < lo || at(i + 1) > hi) return 0;
  for (size_t k = 2; k < n; ++k)
    if (at(i + k) < 0x80 || at(i + k) > 0xbf) return 0;
  return n;
}

}  // namespace

std::string json_string(const std::string &text) {
  std::string out = "\"";
  for (size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const size_t n = utf8_length(text, i);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20 || c == 0x7f || n == 0) {
      // Control characters, and bytes that are not UTF-8 (a file name in
      // Latin-1, say), as \u00XX: JSON must be UTF-8.
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out.append(text, i, n);
      i += n;
      continue;
    }
    ++i;
  }
  return out + "\"";
}

int exit_status(const std::exception &e, int usage, int other) {
  const auto *error = dynamic_cast<const carmen::Error *>(&e);
  if (error != nullptr && error->code() == carmen::ErrorCode::Usage) return usage;
  // A bad --vasco_KEY value is the command line's: a usage error too.
  const auto *file_error = dynamic_cast<const carmen::FileError *>(&e);
  if (file_error != nullptr && file_error->file() == carmen::ParamFile::kCommandLine) return usage;
  return other;
}

uint64_t parse_mebibytes(const std::string &text, const std::string &option) {
  uint64_t mib = 0;
  const char *end = text.data() + text.size();
  const auto [stop, ec] = std::from_chars(text.data(), end, mib);
  const bool digits_only = !text.empty() && stop == end && text.find_first_not_of("0123456789") == std::string::npos;
  if (!digits_only || ec != std::errc())
    throw carmen::Error(carmen::ErrorCode::Usage, option + " " + text + ": not a whole number of MiB from 0 to " +
                                                      std::to_string(UINT64_MAX >> 20));
  if (mib > (UINT64_MAX >> 20))
    throw carmen::Error(carmen::ErrorCode::Usage, option + " " + text + ": more than the largest budget, " +
                                                      std::to_string(UINT64_MAX >> 20) + " MiB");
  return mib << 20;
}

std::string input_path(const std::string &arg) { return arg == kStdio ? "/dev/stdin" : arg; }

StdoutFile::StdoutFile(const std::string &extension) {
  // The directory is made, then registered for removal on a signal: no
  // signal may come in between.
  const carmen::SignalsWait registered_as_made;
  const char *tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/vasco_stdout.XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr)
    throw carmen::Error(carmen::ErrorCode::Io, "cannot make a temporary directory for the output '-': " +
                                                   std::string(std::strerror(errno)));
  dir_ = pattern;
  path_ = dir_ + "/stdout" + extension;
  dir_on_signal_ = std::make_unique<carmen::TemporaryOnSignal>(dir_);
  path_on_signal_ = std::make_unique<carmen::TemporaryOnSignal>(path_);
}

StdoutFile::~StdoutFile() {
  ::unlink(path_.c_str());
  ::rmdir(dir_.c_str());
}

void StdoutFile::send() const {
  FILE *in = std::fopen(path_.c_str(), "rb");
  // Open, the file and its directory can go at once: whatever ends the copy
  // (a closed pipe's SIGPIPE, a signal) leaves nothing behind.
  ::unlink(path_.c_str());
  ::rmdir(dir_.c_str());
  if (in == nullptr) throw carmen::Error(carmen::ErrorCode::Io, "the output '-' was not made");
  char buf[1 << 16];
  size_t n;
  bool ok = true;
  while (ok && (n = std::fread(buf, 1, sizeof buf, in)) > 0) ok = std::fwrite(buf, 1, n, stdout) == n;
  ok = ok && !std::ferror(in);
  std::fclose(in);
  if (!ok || std::fflush(stdout) != 0)
    throw carmen::Error(carmen::ErrorCode::Io, "standard output refused the map: " + std::string(std::strerror(errno)));
}

void check_stdout_writable(const std::string &why) {
  const int flags = ::fcntl(STDOUT_FILENO, F_GETFL);
  if (flags == -1 || (flags & O_ACCMODE) == O_RDONLY)
    throw carmen::Error(carmen::ErrorCode::Io, "standard output is " +
                                                   std::string(flags == -1 ? "closed" : "not open for writing") +
                                                   ": " + why + " has nowhere to go");
}

}  // namespace cli
