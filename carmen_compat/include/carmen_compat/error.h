// error.h — the one error type of the project: a code saying what kind of
// failure it is, set where the failure happens (zstd's error enum is the
// model), and a message for people. Every layer above switches on code():
// the C APIs' status values, log2map's exit status, Python's exception
// classes. Nothing searches a message for words.
#ifndef CARMEN_COMPAT_ERROR_H
#define CARMEN_COMPAT_ERROR_H

#include <stdexcept>
#include <string>

namespace carmen {

enum class ErrorCode {
  Usage,        // a bad argument or option from the caller: a NULL pointer, a bad parameter, an unknown name
  BadInput,     // a file or array that cannot be parsed or trusted (FileError: names the file and line)
  TooLarge,     // what was asked for is beyond a hard limit (grid cells, beam counts, fixed-point range)
  OutOfMemory,  // over the memory budget the caller set, or an allocation failed
  NoGpu,        // the GPU backend cannot run here (not compiled in, no device, driver too old)
  State,        // the call does not fit the object's state (finish before any insert)
  Io,           // the file system refused: cannot open, write, rename, lock
  Internal,     // a bug of ours, or a CUDA failure we did not foresee
};

// A short lower-case name of a code ("bad input"), for messages and tests.
inline const char *error_code_name(ErrorCode code) {
  switch (code) {
    case ErrorCode::Usage: return "usage";
    case ErrorCode::BadInput: return "bad input";
    case ErrorCode::TooLarge: return "too large";
    case ErrorCode::OutOfMemory: return "out of memory";
    case ErrorCode::NoGpu: return "no GPU";
    case ErrorCode::State: return "state";
    case ErrorCode::Io: return "I/O";
    case ErrorCode::Internal: return "internal";
  }
  return "internal";
}

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string &message) : std::runtime_error(message), code_(code) {}
  ErrorCode code() const { return code_; }

 private:
  ErrorCode code_;
};

// Bad input (or an I/O failure) of one file. what() is "FILE:LINE: message"
// when a line is known, else "FILE: message".
class FileError : public Error {
 public:
  FileError(std::string file, long line, const std::string &message, ErrorCode code = ErrorCode::BadInput)
      : Error(code, format(file, line, message)), file_(std::move(file)), line_(line), message_(message) {}
  FileError(std::string file, const std::string &message, ErrorCode code = ErrorCode::BadInput)
      : FileError(std::move(file), 0, message, code) {}

  const std::string &file() const { return file_; }
  long line() const { return line_; }                      // 0 when no line applies
  const std::string &message() const { return message_; }  // without the location

  static std::string format(const std::string &file, long line, const std::string &message) {
    return line > 0 ? file + ":" + std::to_string(line) + ": " + message : file + ": " + message;
  }

 private:
  std::string file_;
  long line_;
  std::string message_;
};

// `text` fit for a terminal: control characters (escape sequences from a
// hostile file among them) shown as \xNN instead of being sent raw.
inline std::string printable(const std::string &text) {
  static const char hex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (unsigned char c : text) {
    if (c < 0x20 || c == 0x7f) {
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

}  // namespace carmen

#endif  // CARMEN_COMPAT_ERROR_H
