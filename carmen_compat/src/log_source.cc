// Opening and reading a log's bytes. See log_source.h.
#include "log_source.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <exception>

#include "carmen_compat/error.h"
#include "carmen_compat/file_names.h"
#include "gzip_stream.h"

namespace carmen {

namespace {

std::string errno_text(const char *what) { return std::string(what) + ": " + std::strerror(errno); }

}  // namespace

LogSource::LogSource(const std::string &path, int fifo_wait_ms, std::size_t block_size)
    : name_(path == "-" ? kStdinName : path) {
  const int fd = open_fd(path);
  try {
    check_kind(fd);
    if (!regular_ && path != "-") wait_for_data(fd, fifo_wait_ms);
  } catch (...) {
    ::close(fd);
    throw;
  }
  fp_ = ::fdopen(fd, "rb");
  if (!fp_) {
    ::close(fd);
    fail(errno_text("cannot open"));
  }
  sniff(path, block_size);
}

LogSource::~LogSource() {
  inflater_.reset();  // its thread reads fp_
  if (fp_) std::fclose(fp_);
}

void LogSource::fail(const std::string &message, bool io) const {
  throw FileError(name_, 0, message, io ? ErrorCode::Io : ErrorCode::BadInput);
}

// A FIFO opened for reading blocks until a writer opens it: O_NONBLOCK
// returns at once, and is cleared again so that reads wait for data.
int LogSource::open_fd(const std::string &path) {
  if (path == "-") {
    const int fd = ::dup(STDIN_FILENO);
    if (fd < 0) fail(errno_text("cannot read standard input"));
    return fd;
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) fail(errno_text("cannot open"));
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) < 0) {
    ::close(fd);
    fail(errno_text("cannot open"));
  }
  return fd;
}

void LogSource::check_kind(int fd) {
  struct stat st;
  if (::fstat(fd, &st) != 0) fail(errno_text("cannot stat"));
  if (S_ISDIR(st.st_mode)) fail("is a directory, not a log file", false);
  regular_ = S_ISREG(st.st_mode);
  size_ = regular_ ? static_cast<uint64_t>(st.st_size) : 0;
}

// Waits for the first byte (or the end) of a FIFO or device; a FIFO nobody
// writes to would otherwise block the reader forever.
void LogSource::wait_for_data(int fd, int wait_ms) const {
  struct pollfd p = {fd, POLLIN, 0};
  int r;
  do {
    r = ::poll(&p, 1, wait_ms);  // < 0: no limit
  } while (r < 0 && errno == EINTR);
  if (r < 0) fail(errno_text("cannot wait for data"));
  if (r == 0)
    fail("no data within " + std::to_string(wait_ms) +
         " ms: nothing writes to this FIFO (start the writer, or raise LogReaderOptions::fifo_wait_ms)");
}

// Reads the first two bytes (kept, to be handed out first: nothing is
// rewound) and starts inflating when they are gzip's magic and the name ends
// in ".gz" or the input is a pipe or standard input (which have no name to go
// by: a tool's "-" is /dev/stdin, a file redirected there is regular).
void LogSource::sniff(const std::string &path, std::size_t block_size) {
  char magic[2] = {0, 0};
  const std::size_t got = std::fread(magic, 1, 2, fp_);
  if (std::ferror(fp_)) fail(errno_text("read error"));
  if (got == 0) fail("empty file", false);
  prefix_.assign(magic, got);
  comp_read_ = got;
  gzip_magic_ = got == 2 && static_cast<unsigned char>(magic[0]) == 0x1f &&
                static_cast<unsigned char>(magic[1]) == 0x8b;
  // As zlib's gzread: a .gz name with non-gzip content is read as it is.
  gz_ = gzip_magic_ && (ends_with(path, ".gz") || !regular_ || path == "/dev/stdin");
  if (!gz_) return;
  try {
    inflater_ = std::make_unique<gzip::BackgroundInflater>(fp_, block_size, prefix_);
  } catch (const std::exception &e) {
    fail(std::string("cannot start inflating: ") + e.what());
  }
  prefix_.clear();
}

std::size_t LogSource::read(char *dst, std::size_t cap) {
  return gz_ ? read_gz(dst, cap) : read_plain(dst, cap);
}

std::size_t LogSource::read_plain(char *dst, std::size_t cap) {
  std::size_t n = std::min(cap, prefix_.size());
  std::memcpy(dst, prefix_.data(), n);
  prefix_.erase(0, n);
  if (n == cap) return n;
  const std::size_t got = std::fread(dst + n, 1, cap - n, fp_);
  comp_read_ += got;
  n += got;
  if (n < cap) {
    if (std::ferror(fp_)) error_ = errno_text("read error");
    else eof_ = true;
  }
  return n;
}

std::size_t LogSource::read_gz(char *dst, std::size_t cap) {
  std::size_t n = 0;
  while (n < cap) {
    bool eof = false;
    std::string error;
    const std::size_t got = inflater_->read(dst + n, cap - n, &eof, &error);
    n += got;
    if (got == 0) {
      if (!error.empty()) error_ = error;
      else eof_ = true;
      break;
    }
  }
  return n;
}

uint64_t LogSource::compressed_read() const {
  return inflater_ ? inflater_->compressed_read() : comp_read_;
}

}  // namespace carmen
