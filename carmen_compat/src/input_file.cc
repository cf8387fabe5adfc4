#include "carmen_compat/input_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include "carmen_compat/error.h"

namespace carmen {

namespace {

const char *kind_of(mode_t mode) {
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

}  // namespace

uint64_t require_regular_file(const std::string &path, const std::string &what) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return 0;  // the open that follows names the error
  if (S_ISREG(st.st_mode)) return static_cast<uint64_t>(st.st_size);
  throw FileError(path, std::string("is ") + kind_of(st.st_mode) + ", not a regular file: " + what +
                            " is read whole; give a file",
                  ErrorCode::Io);
}

}  // namespace carmen
