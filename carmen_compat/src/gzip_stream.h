// Inflating a gzip file for the log reader (internal to carmen_compat).
//
// Three jobs, one class each: MemberDecoder decodes deflate data (ISA-L's
// igzip when the build found it, about 3.5x zlib's speed; zlib otherwise);
// GzipInflater applies the file-level rules on top of it (members one after
// another, zero padding between them, errors as text naming the place);
// BackgroundInflater runs a GzipInflater on its own thread, ahead of the
// parser.
#ifndef CARMEN_COMPAT_SRC_GZIP_STREAM_H
#define CARMEN_COMPAT_SRC_GZIP_STREAM_H

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace carmen {
namespace gzip {

enum class Codec { ZLIB, ISAL };

// Both libraries count bytes in 32 bits: a larger buffer is taken in parts,
// this many bytes at a time (the decoders here, the writer in gzip_write.h).
inline uint32_t clamp32(std::size_t n) {
  return static_cast<uint32_t>(n < UINT32_MAX ? n : UINT32_MAX);
}

// ISAL when this build has ISA-L, else ZLIB. zlib is always built in, so
// tests can hold the two to the same results.
Codec default_codec();
bool codec_available(Codec codec);
const char *codec_name(Codec codec);

// Decodes gzip members (header, deflate data, checked trailer), one at a time.
class MemberDecoder {
 public:
  enum class Status {
    OK,         // progress made, or none possible without more input
    MEMBER_END, // the member's trailer was read and checked
    BAD_DATA,   // message() says what
    NO_MEMORY
  };
  static std::unique_ptr<MemberDecoder> create(Codec codec);
  virtual ~MemberDecoder() = default;

  // Decodes from in (in_len bytes) into out (out_len bytes of room); advances
  // in and out past what was consumed and produced.
  virtual Status decode(const unsigned char *&in, std::size_t &in_len, unsigned char *&out,
                        std::size_t &out_len) = 0;
  // Ready for the next member.
  virtual void reset() = 0;
  // After BAD_DATA: what was wrong, in zlib's words where zlib has them
  // ("incorrect data check", "invalid distance too far back", ...).
  virtual std::string message() const = 0;
};

// Inflates a gzip file (several members and zero padding between them
// allowed, as gzip -t accepts) into the caller's buffer. Errors are not
// thrown: they end the stream with a message, delivered after the good bytes.
// With either codec a file gives zlib's bytes and zlib's verdict: a member
// ISA-L finds damaged is decoded again with zlib (replay_with_zlib). Where
// ISA-L reads further into damage than zlib before it fails (a Huffman table
// zlib calls incomplete, say), bytes it delivered before failing stay
// delivered; the verdict is still zlib's.
class GzipInflater {
 public:
  // in_chunk: compressed bytes per fread (tests make it small, to cut the
  // gzip headers and trailers across reads). prefix: the file's first bytes,
  // already read from fp by the caller (to sniff the magic without seeking a
  // pipe); inflated before what fp holds.
  explicit GzipInflater(std::FILE *fp, Codec codec = default_codec(),
                        std::size_t in_chunk = std::size_t(256) << 10, const std::string &prefix = {});
  GzipInflater(const GzipInflater &) = delete;
  GzipInflater &operator=(const GzipInflater &) = delete;

  // Fills dst with up to cap bytes; fewer only at the end of the stream, when
  // `eof` or `error` is set.
  std::size_t read(char *dst, std::size_t cap, bool *eof, std::string *error);
  uint64_t compressed_read() const { return comp_read_.load(std::memory_order_relaxed); }

 private:
  bool refill(std::string *error);
  bool skip_padding(bool *eof);
  bool step(unsigned char *&out, std::size_t &room, bool *eof, std::string *error);
  bool replay_with_zlib();
  bool redo_delivered(bool *eof, std::string *error);
  std::string fault(MemberDecoder::Status status) const;

  std::FILE *fp_;
  Codec codec_;
  std::unique_ptr<MemberDecoder> dec_;
  std::vector<unsigned char> in_;
  const unsigned char *next_in_ = nullptr;
  std::size_t avail_in_ = 0;
  bool in_eof_ = false;
  uint64_t file_pos_ = 0;      // compressed bytes taken from the file
  uint64_t member_start_ = 0;  // the current member's offset in the file
  uint64_t discard_ = 0;       // bytes a replayed member must make before any is delivered
  bool after_member_ = false;  // a member ended; nothing of the next one was read yet
  uint64_t members_ = 0;       // members ended so far
  uint64_t member_out_ = 0;    // bytes out of the current member
  uint64_t produced_ = 0;      // bytes out of all members
  std::atomic<uint64_t> comp_read_{0};
};

// Runs a GzipInflater on its own thread, kQueuedBlocks blocks ahead of the
// parser: inflating overlaps parsing. Blocks come out in order; the end (eof
// or error) after the last. Memory: kQueuedBlocks + 1 blocks of block_size.
class BackgroundInflater {
 public:
  // prefix: as GzipInflater's.
  BackgroundInflater(std::FILE *fp, std::size_t block_size, const std::string &prefix = {});
  ~BackgroundInflater();

  // Copies up to cap bytes of the stream into dst; 0 at the end, with `eof`
  // or `error` set.
  std::size_t read(char *dst, std::size_t cap, bool *eof, std::string *error);
  uint64_t compressed_read() const { return inflater_.compressed_read(); }

 private:
  struct Block {
    std::vector<char> bytes;
    std::size_t pos = 0;
  };
  static constexpr std::size_t kQueuedBlocks = 4;

  void produce();
  void produce_blocks();

  GzipInflater inflater_;
  const std::size_t block_size_;
  std::mutex m_;
  std::condition_variable data_, space_;
  std::deque<Block> ready_;
  std::vector<std::vector<char>> spare_;
  bool stop_ = false, finished_ = false, eof_ = false;
  std::string error_;
  std::thread thread_;  // last: starts once everything above exists
};

}  // namespace gzip
}  // namespace carmen

#endif  // CARMEN_COMPAT_SRC_GZIP_STREAM_H
