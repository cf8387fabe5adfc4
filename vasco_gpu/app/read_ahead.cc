#include "read_ahead.h"

namespace cli {

ReadAhead::ReadAhead(size_t inputs, size_t in_flight, size_t most, uint64_t budget)
    : in_flight_max_(in_flight < 1 ? 1 : in_flight), most_(most < 1 ? 1 : most), budget_(budget),
      bytes_(inputs, 0) {}

bool ReadAhead::may_admit(size_t i) const {
  if (stopped_ || i >= bytes_.size()) return false;
  if (i <= taken_) return true;  // a mapper waits for it (or will next)
  if (in_flight_ >= in_flight_max_ || i - taken_ >= most_) return false;
  const uint64_t mean = reads_ > 0 ? read_bytes_ / reads_ : 0;
  return held_ + (in_flight_ + 1) * mean <= budget_;
}

std::vector<size_t> ReadAhead::admit() {
  std::vector<size_t> now;
  while (may_admit(next_)) {
    now.push_back(next_++);
    ++in_flight_;
  }
  return now;
}

void ReadAhead::taken(size_t i) {
  if (i + 1 > taken_) taken_ = i + 1;
}

void ReadAhead::read(size_t i, uint64_t bytes) {
  if (i >= bytes_.size()) return;
  if (in_flight_ > 0) --in_flight_;
  bytes_[i] = bytes;
  held_ += bytes;
  if (bytes > 0) {
    read_bytes_ += bytes;
    ++reads_;
  }
}

void ReadAhead::released(size_t i) {
  if (i >= bytes_.size()) return;
  held_ -= bytes_[i];
  bytes_[i] = 0;
}

}  // namespace cli
