// input_file.h — what a file read whole must be: a regular file. A FIFO that
// nobody writes would block the open (or the read) forever, and a device may
// never end; a log is the exception (LogSource waits for a FIFO's first byte,
// with a limit), and "-" is standard input where a tool takes it.
#ifndef CARMEN_COMPAT_INPUT_FILE_H
#define CARMEN_COMPAT_INPUT_FILE_H

#include <cstdint>
#include <string>

namespace carmen {

// Throws FileError (ErrorCode::Io) naming `path` and what it is when it is not
// a regular file (a symlink to one is): "is a FIFO, not a regular file: a
// carmen.ini is read whole; give a file". `what`: what the file is for ("a
// carmen.ini"). A path that does not exist is left to the caller's open,
// whose error says so. Returns the file's size when it exists, else 0.
uint64_t require_regular_file(const std::string &path, const std::string &what);

// "a FIFO", "a directory", "a character device", ... for a stat st_mode that
// is not a regular file's (the one wording of inputs and outputs).
const char *file_kind_text(unsigned mode);

}  // namespace carmen

#endif  // CARMEN_COMPAT_INPUT_FILE_H
