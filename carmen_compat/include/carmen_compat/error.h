// Errors that name the file (and the line, where there is one).
#ifndef CARMEN_COMPAT_ERROR_H
#define CARMEN_COMPAT_ERROR_H

#include <stdexcept>
#include <string>

namespace carmen {

// Bad input: a file that cannot be read, parsed or trusted. what() is
// "FILE:LINE: message" when a line is known, else "FILE: message".
class FileError : public std::runtime_error {
 public:
  FileError(std::string file, long line, const std::string &message)
      : std::runtime_error(format(file, line, message)),
        file_(std::move(file)), line_(line), message_(message) {}
  FileError(std::string file, const std::string &message) : FileError(std::move(file), 0, message) {}

  const std::string &file() const { return file_; }
  long line() const { return line_; }             // 0 when no line applies
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
