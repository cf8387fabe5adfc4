// Shared by the files that implement CARMEN's map_io C API (map_io.cc,
// map_io_tools.cc, map_io_hmap.cc): every C entry point runs its body through
// guarded(), so bad input becomes a message on stderr and -1, never an
// exception crossing into C.
#ifndef CARMEN_COMPAT_MAP_IO_SUPPORT_H
#define CARMEN_COMPAT_MAP_IO_SUPPORT_H

#include <cstdio>
#include <exception>
#include <new>
#include <stdexcept>
#include <string>

#include "carmen/carmen_stdio.h"
#include "carmen_compat/error.h"

namespace carmen::map_io_detail {

inline void report(const char *func, const std::string &msg) {
  std::fprintf(stderr, "%s: %s\n", func, msg.c_str());
}

// Runs `body`; any exception becomes a message on stderr and -1.
template <typename F>
int guarded(const char *func, const char *filename, F &&body) {
  try {
    return body();
  } catch (const carmen::FileError &e) {
    report(func, e.what());
  } catch (const std::bad_alloc &) {
    report(func, std::string(filename ? filename : "map") + ": out of memory");
  } catch (const std::exception &e) {
    report(func, std::string(filename ? filename + std::string(": ") : std::string()) + e.what());
  } catch (...) {
    report(func, "unexpected error");
  }
  return -1;
}

inline void need_name(const char *filename) {
  if (filename == nullptr) throw std::invalid_argument("no file name given");
}

// Writes all of `bytes` or throws.
inline void put_bytes(carmen_FILE *fp, const std::string &bytes) {
  if (fp == nullptr) throw std::invalid_argument("no file given (NULL carmen_FILE)");
  if (carmen_fwrite(bytes.data(), 1, bytes.size(), fp) != bytes.size())
    throw std::runtime_error("write failed");
}

}  // namespace carmen::map_io_detail

#endif  // CARMEN_COMPAT_MAP_IO_SUPPORT_H
