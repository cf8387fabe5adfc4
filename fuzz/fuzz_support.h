// fuzz_support.h — what the libFuzzer targets share: a private temporary
// file for parsers that read files, and a bounded byte reader.
#ifndef VASCO_FUZZ_SUPPORT_H
#define VASCO_FUZZ_SUPPORT_H

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace fuzz {

// Writes the input to a file of this process named with `suffix` (".log",
// ".log.gz", ".map", ...), which parsers judge by name; removed on scope exit.
class InputFile {
 public:
  InputFile(const uint8_t *data, size_t size, const char *suffix) {
    const char *tmp = std::getenv("TMPDIR");
    path_ = std::string(tmp ? tmp : "/tmp") + "/vasco_fuzz_" + std::to_string(::getpid()) + suffix;
    std::FILE *f = std::fopen(path_.c_str(), "wb");
    if (f == nullptr) std::abort();
    if (size) std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  ~InputFile() { std::remove(path_.c_str()); }
  const std::string &path() const { return path_; }

 private:
  std::string path_;
};

// Consumes the input as little-endian numbers; zeros once it runs out.
class Bytes {
 public:
  Bytes(const uint8_t *data, size_t size) : p_(data), n_(size) {}
  uint8_t u8() {
    if (n_ == 0) return 0;
    --n_;
    return *p_++;
  }
  uint32_t u32() {
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(u8()) << (8 * i);
    return v;
  }
  float f32() {
    const uint32_t b = u32();
    float v;
    std::memcpy(&v, &b, 4);
    return v;
  }
  // A double in [lo, hi] (never NaN): for poses and parameters.
  double in(double lo, double hi) { return lo + (hi - lo) * (u32() / 4294967295.0); }
  size_t left() const { return n_; }

 private:
  const uint8_t *p_;
  size_t n_;
};

}  // namespace fuzz

#endif  // VASCO_FUZZ_SUPPORT_H
