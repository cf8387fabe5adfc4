// Where a log's text comes from (internal to carmen_compat): a file, a FIFO
// or standard input ("-"), plain or gzip, read once from start to end and
// never rewound, so that pipes work as files do.
#ifndef CARMEN_COMPAT_SRC_LOG_SOURCE_H
#define CARMEN_COMPAT_SRC_LOG_SOURCE_H

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

namespace carmen {

namespace gzip {
class BackgroundInflater;
}

class LogSource {
 public:
  // The name errors give standard input ("-").
  static constexpr const char *kStdinName = "<stdin>";

  // Opens `path` ("-": standard input) and sniffs gzip from its first two
  // bytes. A FIFO, pipe or device named by path is opened without waiting
  // for a writer, then waited on for at most fifo_wait_ms (< 0: no limit)
  // for its first byte. block_size: bytes inflated ahead
  // per block. Throws FileError naming the file.
  LogSource(const std::string &path, int fifo_wait_ms, std::size_t block_size);
  ~LogSource();
  LogSource(const LogSource &) = delete;
  LogSource &operator=(const LogSource &) = delete;

  // Up to cap bytes of text; fewer only at the end, when eof() or error() is set.
  std::size_t read(char *dst, std::size_t cap);
  bool eof() const { return eof_; }
  const std::string &error() const { return error_; }  // "" unless reading failed

  const std::string &name() const { return name_; }  // the path, or kStdinName
  uint64_t size() const { return size_; }             // 0 when unknown (a pipe)
  uint64_t compressed_read() const;
  bool gz() const { return gz_; }                  // inflating
  bool gzip_magic() const { return gzip_magic_; }  // the data starts with 1f 8b

 private:
  [[noreturn]] void fail(const std::string &message, bool io = true) const;
  int open_fd(const std::string &path);
  void check_kind(int fd);
  void wait_for_data(int fd, int wait_ms) const;
  void sniff(const std::string &path, std::size_t block_size);
  std::size_t read_plain(char *dst, std::size_t cap);
  std::size_t read_gz(char *dst, std::size_t cap);

  std::string name_;
  std::FILE *fp_ = nullptr;
  bool regular_ = false;
  uint64_t size_ = 0;
  uint64_t comp_read_ = 0;  // plain input; a .gz's count is its inflater's
  std::string prefix_;      // sniffed bytes not yet handed out (plain input)
  bool gzip_magic_ = false, gz_ = false;
  std::unique_ptr<gzip::BackgroundInflater> inflater_;
  bool eof_ = false;
  std::string error_;
};

}  // namespace carmen

#endif  // CARMEN_COMPAT_SRC_LOG_SOURCE_H
