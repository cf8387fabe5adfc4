#include "read_ahead.h"

#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <utility>

namespace cli {

ReadAhead::ReadAhead(size_t inputs, size_t in_flight, size_t most, uint64_t budget, std::vector<uint64_t> estimates,
                     uint64_t worst)
    : in_flight_max_(in_flight < 1 ? 1 : in_flight), most_(most < 1 ? 1 : most), budget_(budget),
      worst_(worst > budget ? worst : budget), estimates_(std::move(estimates)), bytes_(inputs, 0),
      reserved_for_(inputs, 0), expected_for_(inputs, 0) {
  estimates_.resize(inputs, 0);
}

// What input i's read is counted at while it is under way: its estimate,
// or the mean read so far where that is more.
uint64_t ReadAhead::reservation(size_t i) const {
  const uint64_t mean = reads_ > 0 ? read_bytes_ / reads_ : 0;
  return estimates_[i] > mean ? estimates_[i] : mean;
}

// What input i's read is expected to hold while it is under way: before
// any read ended (or, for an input with an estimate, before a read with one
// ended: a pipe's says nothing of a file's share), the most it may; after,
// its estimate times the largest share of their estimates the reads came
// to, or the mean read where that is more (no estimate); never more than
// the most.
uint64_t ReadAhead::expectation(size_t i) const {
  const uint64_t most = reservation(i);
  if (reads_ == 0 || (share_ == 0 && estimates_[i] > 0)) return most;
  const uint64_t mean = read_bytes_ / reads_;
  const double scaled = static_cast<double>(estimates_[i]) * share_;
  const uint64_t expect = scaled >= static_cast<double>(most) ? most : static_cast<uint64_t>(scaled);
  return expect > mean ? expect : mean;
}

// Whether `more` bytes fit beside `held` and `counted` within `limit`
// (no overflow for huge estimates: a read of one may be under way, let
// through as the next a mapper takes).
static bool fits(uint64_t held, uint64_t counted, uint64_t more, uint64_t limit) {
  return more <= limit && counted <= limit - more && held <= limit - more - counted;
}

bool ReadAhead::may_admit(size_t i) const {
  if (stopped_ || i >= bytes_.size()) return false;
  if (i <= taken_) return true;  // a mapper waits for it (or will next)
  if (under_way_.size() >= in_flight_max_ || i - taken_ >= most_) return false;
  return fits(held_, expected_, expectation(i), budget_) && fits(held_, reserved_, reservation(i), worst_);
}

std::vector<size_t> ReadAhead::admit() {
  std::vector<size_t> now;
  while (may_admit(next_)) {
    reserved_for_[next_] = reservation(next_);
    reserved_ += reserved_for_[next_];
    expected_for_[next_] = expectation(next_);
    expected_ += expected_for_[next_];
    under_way_.push_back(next_);
    now.push_back(next_++);
  }
  return now;
}

void ReadAhead::taken(size_t i) {
  if (i + 1 > taken_) taken_ = i + 1;
}

void ReadAhead::read(size_t i, uint64_t bytes) {
  if (i >= bytes_.size()) return;
  reserved_ -= reserved_for_[i];
  reserved_for_[i] = 0;
  expected_ -= expected_for_[i];
  expected_for_[i] = 0;
  const auto at = std::find(under_way_.begin(), under_way_.end(), i);
  if (at != under_way_.end()) {
    *at = under_way_.back();
    under_way_.pop_back();
  }
  bytes_[i] = bytes;
  held_ += bytes;
  if (bytes > 0) {
    read_bytes_ += bytes;
    ++reads_;
    if (estimates_[i] > 0) {
      const double share = static_cast<double>(bytes) / static_cast<double>(estimates_[i]);
      if (share > share_) {
        share_ = share;
        recount_expected();
      }
    }
  }
}

// The reads under way counted again at what they are now expected to hold
// (what was let through before the first read ended counted at the most).
void ReadAhead::recount_expected() {
  expected_ = 0;
  for (size_t k : under_way_) {
    const uint64_t e = expectation(k);  // the mean may have grown since k's reservation
    expected_for_[k] = e < reserved_for_[k] ? e : reserved_for_[k];
    expected_ += expected_for_[k];
  }
}

void ReadAhead::released(size_t i) {
  if (i >= bytes_.size()) return;
  held_ -= bytes_[i];
  bytes_[i] = 0;
}

namespace {

uint64_t saturating_product(uint64_t a, uint64_t b) { return b != 0 && a > UINT64_MAX / b ? UINT64_MAX : a * b; }

// The text's size of a gzip file of `compressed` bytes whose trailer gives
// `isize` (the size mod 2^32 of its last member's text): that size, unless
// the file is much larger than it (several members, or a text of 4 GiB or
// more): then the largest text deflate could have made of the file.
uint64_t gzip_text_bytes(uint64_t compressed, uint64_t isize) {
  // Deflate's stored blocks add 5 bytes per 64 KiB; the header and trailer some more.
  if (isize + isize / 8 + 4096 < compressed) return saturating_product(compressed, kMaxDeflateRatio);
  return isize > compressed ? isize : compressed;
}

}  // namespace

uint64_t parsed_bytes_estimate(const std::string &path, uint64_t cap) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return 0;  // a pipe or device: not known, 0
  uint64_t text = static_cast<uint64_t>(st.st_size);
  if (FILE *f = std::fopen(path.c_str(), "rb")) {
    unsigned char magic[2] = {0, 0}, trailer[4] = {0, 0, 0, 0};
    const bool gzip = std::fread(magic, 1, 2, f) == 2 && magic[0] == 0x1f && magic[1] == 0x8b;
    if (gzip && st.st_size >= 18 && std::fseek(f, -4, SEEK_END) == 0 && std::fread(trailer, 1, 4, f) == 4) {
      const uint64_t isize = trailer[0] | trailer[1] << 8 | trailer[2] << 16 | uint64_t{trailer[3]} << 24;
      text = gzip_text_bytes(text, isize);
    }
    std::fclose(f);
  }
  const uint64_t parsed = saturating_product(text, kParsedPerTextByte);
  return cap > 0 && parsed > cap ? cap : parsed;
}

}  // namespace cli
