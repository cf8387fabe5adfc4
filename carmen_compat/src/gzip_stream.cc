// gzip inflating for the log reader: the two deflate decoders, the file-level
// rules, and the background thread. See gzip_stream.h.
#include "gzip_stream.h"

#include <zlib.h>
#ifdef VASCO_HAVE_ISAL
#include <isa-l/igzip_lib.h>
#endif

#include <sys/types.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <new>
#include <stdexcept>

#include "carmen_compat/termination_signals.h"

namespace carmen {
namespace gzip {

namespace {

constexpr std::size_t kScratch = std::size_t(256) << 10;  // a replay's bytes decoded again per step


class ZlibDecoder final : public MemberDecoder {
 public:
  ZlibDecoder() {
    if (inflateInit2(&zs_, 15 + 16) != Z_OK) throw std::bad_alloc();  // 16: gzip wrapper only
  }
  ~ZlibDecoder() override { inflateEnd(&zs_); }

  Status decode(const unsigned char *&in, std::size_t &in_len, unsigned char *&out,
                std::size_t &out_len) override {
    const uInt in_take = clamp32(in_len), out_take = clamp32(out_len);
    zs_.next_in = const_cast<Bytef *>(in);
    zs_.avail_in = in_take;
    zs_.next_out = out;
    zs_.avail_out = out_take;
    const int ret = inflate(&zs_, Z_NO_FLUSH);
    in = zs_.next_in;
    in_len -= in_take - zs_.avail_in;
    out = zs_.next_out;
    out_len -= out_take - zs_.avail_out;
    switch (ret) {
      case Z_STREAM_END: return Status::MEMBER_END;
      case Z_OK:
      case Z_BUF_ERROR: return Status::OK;  // Z_BUF_ERROR: no progress without more input
      case Z_MEM_ERROR: return Status::NO_MEMORY;
      default:
        message_ = zs_.msg ? zs_.msg : "invalid data";
        return Status::BAD_DATA;
    }
  }
  void reset() override { inflateReset(&zs_); }
  std::string message() const override { return message_; }

 private:
  z_stream zs_{};
  std::string message_;
};

#ifdef VASCO_HAVE_ISAL
class IsalDecoder final : public MemberDecoder {
 public:
  // The state is 85 KiB: on the heap, not in the reader's object.
  IsalDecoder() : st_(new inflate_state) { reset(); }

  Status decode(const unsigned char *&in, std::size_t &in_len, unsigned char *&out,
                std::size_t &out_len) override {
    const uint32_t in_take = clamp32(in_len), out_take = clamp32(out_len);
    st_->next_in = const_cast<uint8_t *>(in);
    st_->avail_in = in_take;
    st_->next_out = out;
    st_->avail_out = out_take;
    const int ret = inflate_until_moved();
    keep_head(in, in_take - st_->avail_in);
    in = st_->next_in;
    in_len -= in_take - st_->avail_in;
    out = st_->next_out;
    out_len -= out_take - st_->avail_out;
    if (ret < 0 || (head_len_ == 4 && (head_[3] & 0xE0) != 0)) {
      code_ = ret < 0 ? ret : kReservedFlags;
      return Status::BAD_DATA;
    }
    return st_->block_state == ISAL_BLOCK_FINISH ? Status::MEMBER_END : Status::OK;
  }
  void reset() override {
    isal_inflate_init(st_.get());
    st_->crc_flag = ISAL_GZIP;  // parse the gzip header, check CRC-32 and length
    head_len_ = 0;
  }
  std::string message() const override {
    switch (code_) {
      case kReservedFlags: return "unknown header flags set";
      case ISAL_INVALID_BLOCK: return "invalid deflate block";
      case ISAL_INVALID_SYMBOL: return "invalid literal/length or distance code";
      case ISAL_INVALID_LOOKBACK: return "invalid distance too far back";
      case ISAL_INVALID_WRAPPER: return "incorrect header check";
      case ISAL_UNSUPPORTED_METHOD: return "unknown compression method";
      case ISAL_INCORRECT_CHECKSUM: return "incorrect data check";
      default: return "invalid data (ISA-L error " + std::to_string(code_) + ")";
    }
  }

 private:
  // A call can move the state on (into the trailer check, say) with no byte
  // in or out; the caller reads "nothing moved" as "the input ran out", so
  // go on until something moves or the state stays.
  int inflate_until_moved() {
    for (;;) {
      const isal_block_state before = st_->block_state;
      const uint32_t in_before = st_->avail_in, out_before = st_->avail_out;
      const int ret = isal_inflate(st_.get());
      if (ret != ISAL_DECOMP_OK || st_->block_state == ISAL_BLOCK_FINISH) return ret;
      if (st_->avail_in != in_before || st_->avail_out != out_before) return ret;
      if (st_->block_state == before) return ret;
    }
  }
  // zlib refuses a member whose header sets reserved flag bits; ISA-L ignores
  // them. The first four bytes of each member (as they are consumed) are kept
  // to refuse the same members.
  void keep_head(const unsigned char *in, std::size_t consumed) {
    while (head_len_ < 4 && consumed-- > 0) head_[head_len_++] = *in++;
  }

  static constexpr int kReservedFlags = -100;  // not an ISA-L code
  std::unique_ptr<inflate_state> st_;
  unsigned char head_[4] = {0, 0, 0, 0};
  int head_len_ = 0;
  int code_ = 0;
};
#endif

}  // namespace

Codec default_codec() {
#ifdef VASCO_HAVE_ISAL
  return Codec::ISAL;
#else
  return Codec::ZLIB;
#endif
}

bool codec_available(Codec codec) { return codec == Codec::ZLIB || default_codec() == codec; }

const char *codec_name(Codec codec) { return codec == Codec::ISAL ? "ISA-L" : "zlib"; }

std::unique_ptr<MemberDecoder> MemberDecoder::create(Codec codec) {
#ifdef VASCO_HAVE_ISAL
  if (codec == Codec::ISAL) return std::make_unique<IsalDecoder>();
#endif
  if (codec != Codec::ZLIB) throw std::invalid_argument("this build has no ISA-L");
  return std::make_unique<ZlibDecoder>();
}

// ---------------------------------------------------------------------------

GzipInflater::GzipInflater(std::FILE *fp, Codec codec, std::size_t in_chunk, const std::string &prefix)
    : fp_(fp),
      codec_(codec),
      dec_(MemberDecoder::create(codec)),
      in_(std::max<std::size_t>({in_chunk, prefix.size(), 1})) {
  std::memcpy(in_.data(), prefix.data(), prefix.size());
  next_in_ = in_.data();
  avail_in_ = prefix.size();
  file_pos_ = prefix.size();
  comp_read_.store(file_pos_, std::memory_order_relaxed);
}

std::size_t GzipInflater::read(char *dst, std::size_t cap, bool *eof, std::string *error) {
  auto *out = reinterpret_cast<unsigned char *>(dst);
  std::size_t room = cap;
  while (room > 0) {
    const bool ended = discard_ > 0 ? redo_delivered(eof, error) : step(out, room, eof, error);
    if (ended) break;
  }
  return cap - room;
}

// Reads the next compressed chunk when the last is used up; false on a read error.
bool GzipInflater::refill(std::string *error) {
  if (avail_in_ > 0 || in_eof_) return true;
  const std::size_t n = std::fread(in_.data(), 1, in_.size(), fp_);
  file_pos_ += n;
  if (file_pos_ > comp_read_.load(std::memory_order_relaxed))  // a replay reads some again
    comp_read_.store(file_pos_, std::memory_order_relaxed);
  if (n == 0) {
    if (std::ferror(fp_)) {
      *error = std::string("read error: ") + std::strerror(errno);
      return false;
    }
    in_eof_ = true;
  }
  next_in_ = in_.data();
  avail_in_ = n;
  return true;
}

// Zero bytes after a member are padding (tape and block devices add them;
// gzip -t accepts them): skipped. True when the file ends in them (`eof` set).
bool GzipInflater::skip_padding(bool *eof) {
  while (avail_in_ > 0 && *next_in_ == 0) {
    ++next_in_;
    --avail_in_;
  }
  if (avail_in_ == 0 && in_eof_) *eof = true;
  return *eof;
}

// One decoding step into [out, out + room); true when the stream ended (eof
// or error set).
bool GzipInflater::step(unsigned char *&out, std::size_t &room, bool *eof, std::string *error) {
  if (!refill(error)) return true;
  if (after_member_) {
    if (skip_padding(eof)) return true;
    member_start_ = file_pos_ - avail_in_;
  }
  if (avail_in_ == 0 && !in_eof_) return false;
  unsigned char *const out_before = out;
  const std::size_t in_before = avail_in_, room_before = room;
  const MemberDecoder::Status s = dec_->decode(next_in_, avail_in_, out, room);
  if (s == MemberDecoder::Status::BAD_DATA && replay_with_zlib()) {
    out = out_before;  // this call's bytes may run past the fault: zlib decides
    room = room_before;
    return false;
  }
  const bool moved = avail_in_ != in_before || room != room_before;
  if (moved) after_member_ = false;
  produced_ += room_before - room;
  member_out_ += room_before - room;
  switch (s) {
    case MemberDecoder::Status::MEMBER_END:
      after_member_ = true;  // another gzip member may follow (as gzip -c a b > c makes)
      member_out_ = 0;
      ++members_;
      dec_->reset();
      return false;
    case MemberDecoder::Status::OK:
      if (moved || avail_in_ > 0 || !in_eof_) return false;
      if (replay_with_zlib()) return false;
      *error = "truncated gzip stream: the compressed data ends after " +
               std::to_string(produced_) + " uncompressed bytes, before the end of the stream";
      return true;
    default:
      *error = fault(s);
      return true;
  }
}

// ISA-L can write bytes past a fault before it reports it (a copy from a
// distance too far back, say), holds back the last bytes before a cut, and
// names fewer kinds of fault than zlib. So its verdict on a damaged member is
// not taken: the member is decoded again from its start with zlib, which goes
// on from there, and a damaged file reads the same with either codec. False
// when the file cannot seek back (a pipe): ISA-L's verdict stands.
bool GzipInflater::replay_with_zlib() {
  if (codec_ == Codec::ZLIB) return false;
  if (fseeko(fp_, static_cast<off_t>(member_start_), SEEK_SET) != 0) return false;
  dec_ = MemberDecoder::create(Codec::ZLIB);
  codec_ = Codec::ZLIB;
  file_pos_ = member_start_;
  avail_in_ = 0;
  in_eof_ = false;
  after_member_ = false;
  discard_ = member_out_;  // delivered already: decoded again, not again delivered
  produced_ -= member_out_;
  member_out_ = 0;
  return true;
}

// Decodes (into scratch) part of what a replayed member had delivered; true
// when the stream ended there.
bool GzipInflater::redo_delivered(bool *eof, std::string *error) {
  std::vector<unsigned char> scratch(std::min<std::size_t>(discard_, kScratch));
  unsigned char *out = scratch.data();
  std::size_t room = scratch.size();
  const bool ended = step(out, room, eof, error);
  discard_ -= scratch.size() - room;
  return ended;
}

std::string GzipInflater::fault(MemberDecoder::Status status) const {
  if (status == MemberDecoder::Status::NO_MEMORY) return "out of memory while inflating";
  if (members_ > 0 && member_out_ == 0)
    return "corrupt gzip file: data after the end of the gzip stream is not gzip data";
  return "corrupt gzip stream after " + std::to_string(produced_) + " uncompressed bytes: " +
         dec_->message();
}

// ---------------------------------------------------------------------------

BackgroundInflater::BackgroundInflater(std::FILE *fp, std::size_t block_size, const std::string &prefix)
    : inflater_(fp, default_codec(), std::size_t(256) << 10, prefix), block_size_(block_size),
      thread_(carmen::start_thread([this] { produce(); })) {}

BackgroundInflater::~BackgroundInflater() {
  {
    std::lock_guard<std::mutex> lock(m_);
    stop_ = true;
  }
  space_.notify_all();
  thread_.join();
}

std::size_t BackgroundInflater::read(char *dst, std::size_t cap, bool *eof, std::string *error) {
  std::unique_lock<std::mutex> lock(m_);
  data_.wait(lock, [&] { return !ready_.empty() || finished_; });
  if (ready_.empty()) {
    *eof = eof_;
    *error = error_;
    return 0;
  }
  Block &b = ready_.front();
  const std::size_t n = std::min(cap, b.bytes.size() - b.pos);
  std::memcpy(dst, b.bytes.data() + b.pos, n);
  b.pos += n;
  if (b.pos == b.bytes.size()) {
    spare_.push_back(std::move(b.bytes));
    ready_.pop_front();
    lock.unlock();
    space_.notify_one();
  }
  return n;
}

void BackgroundInflater::produce() {
  try {
    produce_blocks();
  } catch (const std::exception &e) {  // bad_alloc: end the stream with it
    {
      std::lock_guard<std::mutex> lock(m_);
      finished_ = true;
      error_ = std::string("while inflating: ") + e.what();
    }
    data_.notify_one();
  }
}

void BackgroundInflater::produce_blocks() {
  for (;;) {
    std::vector<char> bytes;
    {
      std::unique_lock<std::mutex> lock(m_);
      space_.wait(lock, [&] { return stop_ || ready_.size() < kQueuedBlocks; });
      if (stop_) return;
      if (!spare_.empty()) {
        bytes = std::move(spare_.back());
        spare_.pop_back();
      }
    }
    bytes.resize(block_size_);
    bool eof = false;
    std::string error;
    bytes.resize(inflater_.read(bytes.data(), bytes.size(), &eof, &error));
    {
      std::lock_guard<std::mutex> lock(m_);
      if (!bytes.empty()) ready_.push_back(Block{std::move(bytes), 0});
      if (eof || !error.empty()) {
        finished_ = true;
        eof_ = eof;
        error_ = error;
      }
    }
    data_.notify_one();
    if (eof || !error.empty()) return;
  }
}

}  // namespace gzip
}  // namespace carmen
