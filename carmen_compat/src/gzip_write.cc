// The .gz writer (gzip_write.h): zlib's and ISA-L's encoders behind one
// loop that hands each output buffer to write(2).
#include "gzip_write.h"

#include <unistd.h>
#include <zlib.h>
#ifdef VASCO_HAVE_ISAL
#include <isa-l/igzip_lib.h>
#endif

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <new>
#include <stdexcept>
#include <utility>
#include <vector>

#include "carmen_compat/error.h"

namespace carmen {
namespace gzip {

namespace {

constexpr std::size_t kOut = std::size_t(256) << 10;  // compressed bytes per write(2)

}  // namespace

// One step: consumes what it can of [in, in + in_len) (all of it, unless out
// fills; in and in_len advanced past it), writing into out; `last`: the input
// ends there. Returns the output bytes made; *done once the member's trailer
// is out. The codecs differ only in `run`.
class GzipWriter::Encoder {
 public:
  virtual ~Encoder() = default;
  std::size_t step(const unsigned char *&in, std::size_t &in_len, unsigned char *out, std::size_t out_len,
                   bool last, bool *done) {
    const uint32_t take = clamp32(in_len);
    uint32_t in_left = take, out_left = clamp32(out_len);
    *done = run(in, in_left, out, out_left, last && take == in_len);
    in += take - in_left;
    in_len -= take - in_left;
    return out_len - out_left;
  }

 private:
  // The codec's deflate of in_left bytes at in into out_left bytes at out;
  // both left as what remains after it. finish: no input follows. True once
  // the trailer is out.
  virtual bool run(const unsigned char *in, uint32_t &in_left, unsigned char *out, uint32_t &out_left,
                   bool finish) = 0;
};

namespace {

class ZlibEncoder final : public GzipWriter::Encoder {
 public:
  ZlibEncoder() {
    // 15 + 16: a gzip wrapper; level and memory as gzopen's "wb" has them
    if (deflateInit2(&zs_, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
      throw std::bad_alloc();
  }
  ~ZlibEncoder() override { deflateEnd(&zs_); }

 private:
  bool run(const unsigned char *in, uint32_t &in_left, unsigned char *out, uint32_t &out_left, bool finish) override {
    zs_.next_in = const_cast<Bytef *>(in);
    zs_.avail_in = in_left;
    zs_.next_out = out;
    zs_.avail_out = out_left;
    const int ret = deflate(&zs_, finish ? Z_FINISH : Z_NO_FLUSH);
    if (ret == Z_STREAM_ERROR) throw std::logic_error("zlib's deflate refused its stream (a bug)");
    in_left = zs_.avail_in;
    out_left = zs_.avail_out;
    return ret == Z_STREAM_END;
  }

  z_stream zs_{};
};

#ifdef VASCO_HAVE_ISAL
class IsalEncoder final : public GzipWriter::Encoder {
 public:
  IsalEncoder() : level_buf_(ISAL_DEF_LVL1_DEFAULT) {
    isal_deflate_init(&zs_);
    zs_.gzip_flag = IGZIP_GZIP;  // a gzip header and trailer around the deflate data
    zs_.level = 1;
    zs_.level_buf = level_buf_.data();
    zs_.level_buf_size = static_cast<uint32_t>(level_buf_.size());
  }

 private:
  bool run(const unsigned char *in, uint32_t &in_left, unsigned char *out, uint32_t &out_left, bool finish) override {
    zs_.next_in = const_cast<uint8_t *>(in);
    zs_.avail_in = in_left;
    zs_.next_out = out;
    zs_.avail_out = out_left;
    zs_.end_of_stream = finish ? 1 : 0;
    zs_.flush = NO_FLUSH;
    const int ret = isal_deflate(&zs_);
    if (ret != COMP_OK) throw std::logic_error("ISA-L's deflate refused its stream (a bug): " + std::to_string(ret));
    in_left = zs_.avail_in;
    out_left = zs_.avail_out;
    return zs_.internal_state.state == ZSTATE_END;
  }

  std::vector<uint8_t> level_buf_;
  isal_zstream zs_{};
};
#endif

std::unique_ptr<GzipWriter::Encoder> make_encoder(Codec codec) {
#ifdef VASCO_HAVE_ISAL
  if (codec == Codec::ISAL) return std::make_unique<IsalEncoder>();
#endif
  if (codec != Codec::ZLIB) throw std::invalid_argument("this build has no ISA-L");
  return std::make_unique<ZlibEncoder>();
}

}  // namespace

GzipWriter::GzipWriter(int fd, std::string name, Codec codec) : fd_(fd) {
  try {  // the descriptor is the writer's from here: closed if it cannot be made
    name_ = std::move(name);
    out_.reset(new unsigned char[kOut]);
    enc_ = make_encoder(codec);
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

GzipWriter::~GzipWriter() {
  if (fd_ >= 0) ::close(fd_);
}

void GzipWriter::write(const char *data, std::size_t n) {
  const unsigned char *in = reinterpret_cast<const unsigned char *>(data);
  while (n > 0) {
    bool done = false;
    const std::size_t made = enc_->step(in, n, out_.get(), kOut, false, &done);
    write_out(out_.get(), made);
  }
}

void GzipWriter::close() {
  bool done = false;
  while (!done) {
    const unsigned char *in = nullptr;
    std::size_t n = 0;
    const std::size_t made = enc_->step(in, n, out_.get(), kOut, true, &done);
    write_out(out_.get(), made);
  }
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) throw FileError(name_, std::string("write failed on close: ") + std::strerror(errno));
}

void GzipWriter::write_out(const unsigned char *p, std::size_t n) {
  while (n > 0) {
    const ssize_t k = ::write(fd_, p, n);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) throw FileError(name_, std::string("write failed: ") + std::strerror(k < 0 ? errno : ENOSPC));
    p += k;
    n -= static_cast<std::size_t>(k);
  }
}

}  // namespace gzip
}  // namespace carmen
