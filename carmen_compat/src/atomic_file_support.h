// What atomic_file.cc shares with target_locks.cc: a target's path taken apart, and its I/O error.
#ifndef CARMEN_COMPAT_SRC_ATOMIC_FILE_SUPPORT_H
#define CARMEN_COMPAT_SRC_ATOMIC_FILE_SUPPORT_H

#include <string>

#include "carmen_compat/error.h"

namespace carmen::internal {

// Splits "a/b/c.map" into "a/" and "c.map" (directory keeps its slash).
void split_path(const std::string &path, std::string *dir, std::string *base);

// The directory a path's file lies in, fit for open() and stat().
std::string directory_of(const std::string &path);

// FileError(path, why, ErrorCode::Io).
FileError io_error(const std::string &path, const std::string &why);

}  // namespace carmen::internal

#endif  // CARMEN_COMPAT_SRC_ATOMIC_FILE_SUPPORT_H
