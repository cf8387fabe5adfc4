#include "carmen_compat/input_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include "carmen_compat/error.h"

namespace carmen {

const char *file_kind_text(unsigned mode) {
  const mode_t m = static_cast<mode_t>(mode);
  if (S_ISDIR(m)) return "a directory";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISSOCK(m)) return "a socket";
  return "not a regular file";
}

uint64_t require_regular_file(const std::string &path, const std::string &what) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return 0;  // the open that follows names the error
  if (S_ISREG(st.st_mode)) return static_cast<uint64_t>(st.st_size);
  throw FileError(path, std::string("is ") + file_kind_text(static_cast<unsigned>(st.st_mode)) + ", not a regular file: " + what +
                            " is read whole; give a file",
                  ErrorCode::Io);
}

}  // namespace carmen
