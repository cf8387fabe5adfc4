// The map reader's byte stream: buffered, plain or gzip by the file's name
// (file_names.h's rule), counting its position, and knowing how many bytes
// remain when the file is a plain regular file (so that a size a chunk claims
// can be checked before memory is allocated for it).
#ifndef CARMEN_COMPAT_MAP_FILE_INPUT_H
#define CARMEN_COMPAT_MAP_FILE_INPUT_H

#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace carmen::map_read {

class Input {
 public:
  // Throws carmen::FileError (Io) when the file cannot be opened.
  explicit Input(const std::string &path);
  ~Input();
  Input(const Input &) = delete;
  Input &operator=(const Input &) = delete;

  const std::string &path() const { return path_; }
  bool compressed() const { return gz_ != nullptr; }
  int64_t pos() const { return pos_; }
  // Bytes left in a plain regular file; -1 when unknown (gzip, pipes).
  int64_t remaining() const;

  int peek();
  int get();
  // Reads up to n bytes; fewer only at the end of the data (or on damage).
  size_t read(void *dst, size_t n);
  // Discards up to n bytes; returns how many were there.
  uint64_t skip(uint64_t n);
  // A read error, or for gzip a corrupt or truncated stream; "" when none.
  std::string stream_error() const;

 private:
  size_t raw_read(void *dst, size_t n);
  bool fill();

  std::string path_;
  FILE *fp_ = nullptr;
  gzFile gz_ = nullptr;
  std::vector<unsigned char> buf_;
  size_t head_ = 0, tail_ = 0;
  int64_t pos_ = 0;
  int64_t size_ = -1;
  bool eof_ = false;
};

}  // namespace carmen::map_read

#endif  // CARMEN_COMPAT_MAP_FILE_INPUT_H
