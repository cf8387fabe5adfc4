#include "map_file_input.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "carmen_compat/error.h"
#include "carmen_compat/file_names.h"

namespace carmen::map_read {
namespace {

[[noreturn]] void cannot_open(const std::string &path) {
  throw FileError(path, std::string("cannot open: ") + std::strerror(errno != 0 ? errno : EIO), ErrorCode::Io);
}

}  // namespace

Input::Input(const std::string &path) : path_(path), buf_(1 << 16) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) cannot_open(path);
  if (S_ISDIR(st.st_mode)) throw FileError(path, "is a directory, not a map file", ErrorCode::Io);
  errno = 0;
  if (is_gzip_name(path)) {
    gz_ = gzopen(path.c_str(), "rb");
    if (gz_ == nullptr) cannot_open(path);
    gzbuffer(gz_, 1 << 17);
  } else {
    fp_ = std::fopen(path.c_str(), "rb");
    if (fp_ == nullptr) cannot_open(path);
    if (S_ISREG(st.st_mode)) size_ = static_cast<int64_t>(st.st_size);
  }
}

Input::~Input() {
  if (gz_ != nullptr) gzclose(gz_);
  if (fp_ != nullptr) std::fclose(fp_);
}

int64_t Input::remaining() const { return size_ < 0 ? -1 : std::max<int64_t>(0, size_ - pos_); }

int Input::peek() {
  if (head_ == tail_ && !fill()) return -1;
  return buf_[head_];
}

int Input::get() {
  const int c = peek();
  if (c >= 0) {
    ++head_;
    ++pos_;
  }
  return c;
}

size_t Input::read(void *dst, size_t n) {
  auto *out = static_cast<unsigned char *>(dst);
  size_t done = 0;
  while (done < n) {
    if (head_ < tail_) {
      const size_t k = std::min(n - done, tail_ - head_);
      std::memcpy(out + done, buf_.data() + head_, k);
      head_ += k;
      done += k;
      continue;
    }
    if (eof_) break;
    if (n - done >= buf_.size()) {  // large read: straight into the destination
      const size_t want = std::min(n - done, size_t{1} << 30);
      const size_t got = raw_read(out + done, want);
      done += got;
      if (got < want) eof_ = true;
      continue;
    }
    if (!fill()) break;
  }
  pos_ += static_cast<int64_t>(done);
  return done;
}

uint64_t Input::skip(uint64_t n) {
  uint64_t done = 0;
  while (done < n) {
    if (head_ == tail_ && !fill()) break;
    const size_t k = static_cast<size_t>(std::min<uint64_t>(n - done, tail_ - head_));
    head_ += k;
    done += k;
  }
  pos_ += static_cast<int64_t>(done);
  return done;
}

std::string Input::stream_error() const {
  if (gz_ != nullptr) {
    int err = Z_OK;
    const char *msg = gzerror(gz_, &err);
    if (err != Z_OK && err != Z_STREAM_END) {
      return std::string("cannot be read: the gzip data is corrupt or cut short (zlib: ") + (msg ? msg : "?") +
             ")";
    }
    return {};
  }
  return std::ferror(fp_) ? std::string("cannot be read: ") + std::strerror(errno) : std::string();
}

// gzread takes an unsigned count: callers pass at most 1 GiB.
size_t Input::raw_read(void *dst, size_t n) {
  if (gz_ == nullptr) return std::fread(dst, 1, n, fp_);
  const int got = gzread(gz_, dst, static_cast<unsigned>(n));
  return got < 0 ? 0 : static_cast<size_t>(got);
}

bool Input::fill() {
  if (eof_) return false;
  const size_t got = raw_read(buf_.data(), buf_.size());
  head_ = 0;
  tail_ = got;
  if (got < buf_.size()) eof_ = true;
  return got > 0;
}

}  // namespace carmen::map_read
