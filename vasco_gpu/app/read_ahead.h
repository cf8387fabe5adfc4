// read_ahead.h — which inputs of a batch are read ahead of its mappers.
//
// Reading (inflate + parse) runs on the pool while the mappers map; how far
// it may run ahead decides whether the pool idles while a GPU backend starts
// (0.2-0.3 s, up to a third of a 200-log batch) and how much memory parsed inputs
// hold. Inputs are let through in order while all of these hold: fewer than
// `in_flight` reads are under way (the pool runs only so many at once);
// fewer than `most` inputs are read or being read and not yet taken by a
// mapper; and two byte limits:
// - `budget`, what the inputs read and not yet released hold, each read under
//   way counted at what it is expected to hold: before any read ended, at
//   its input's estimate (parsed_bytes_estimate: what its file may parse to);
//   after, at its estimate scaled by the largest share of its estimate a read
//   came to (the mean size read where there is no estimate, or where that is
//   more);
// - `worst` (at least `budget`), the same with each read under way counted at
//   the most it may hold: its estimate, or the mean size read where that is
//   more. This one holds whatever the inputs parse to.
// A read under way counts from the moment it is let through; once it ends,
// at its size. The estimate is a bound (8 bytes per byte of text) several
// times what a log parses to (fr079's ranges alone, 4 bytes each, are 0.73
// bytes per byte of its text): counted at it, a 1 GiB budget let 14 of 16
// threads read at first and fewer the more was read ahead. The next input a
// mapper will take is let through whatever its size, so a batch of inputs
// larger than the budget still runs, one ahead.
// Not thread-safe: the batch calls it under its own lock.
#ifndef VASCO_GPU_TOOLS_READ_AHEAD_H
#define VASCO_GPU_TOOLS_READ_AHEAD_H

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace cli {

class ReadAhead {
 public:
  // `estimates`: per input, the bytes its read may come to hold (none, or
  // fewer than the inputs: 0 for the rest, the mean read then counting).
  // `worst` 0 (or less than `budget`): `budget`, and each read under way is
  // counted at the most it may hold against it too.
  ReadAhead(size_t inputs, size_t in_flight, size_t most, uint64_t budget, std::vector<uint64_t> estimates = {},
            uint64_t worst = 0);

  // The inputs to start reading now, in order; each is returned once.
  std::vector<size_t> admit();
  // A mapper took input i (the next in order); admit() then lets it through
  // if it was not yet.
  void taken(size_t i);
  // Input i's read ended holding `bytes` (0: it failed, or was not run).
  void read(size_t i, uint64_t bytes);
  // Input i's bytes are given back (mapped, failed or put off).
  void released(size_t i);
  // Nothing more is let through (the batch stops).
  void stop() { stopped_ = true; }

  uint64_t held_bytes() const { return held_; }
  // What the reads under way are counted at: the most each may hold, and
  // what each is expected to hold.
  uint64_t reserved_bytes() const { return reserved_; }
  uint64_t expected_bytes() const { return expected_; }

 private:
  bool may_admit(size_t i) const;
  uint64_t reservation(size_t i) const;
  uint64_t expectation(size_t i) const;
  void recount_expected();

  const size_t in_flight_max_, most_;
  const uint64_t budget_, worst_;
  std::vector<uint64_t> estimates_;  // per input, as given
  std::vector<uint64_t> bytes_;      // per input: held until released
  std::vector<uint64_t> reserved_for_;  // per input: the most it may hold, while its read is under way
  std::vector<uint64_t> expected_for_;  // per input: what it is expected to hold, likewise
  std::vector<size_t> under_way_;       // let through, read not yet ended (how many: the reads at once)
  size_t next_ = 0;                  // the next input to let through
  size_t taken_ = 0;                 // inputs taken by mappers
  uint64_t held_ = 0;                // bytes of inputs read and not released
  uint64_t reserved_ = 0;            // the reads under way's reservations
  uint64_t expected_ = 0;            // and their expectations
  double share_ = 0;                 // the largest share of its estimate a read came to (0: none yet)
  uint64_t read_bytes_ = 0;          // of every read that held something
  size_t reads_ = 0;                 // how many did
  bool stopped_ = false;
};

// The bytes the parsed scans of the input at `path` may come to hold, from
// its file alone, for ReadAhead before the read: its text's size (a plain
// file's size; a gzip file's by the size its trailer gives, or the largest
// deflate allows where that cannot be its text) times kParsedPerTextByte,
// at most `cap` (the reader's own limit on an input's scans; 0: none). 0
// when the file cannot be examined (its read fails at once).
uint64_t parsed_bytes_estimate(const std::string &path, uint64_t cap);

// Parsed bytes per byte of log text, at most: a beam's 4-byte range from
// as few as 2 characters ("0 "), a scan's some 100 bytes of records from a
// line of some 30, and a vector grown by doubling holding up to twice what
// it stores.
constexpr uint64_t kParsedPerTextByte = 8;
// Deflate's largest ratio of output to input bytes.
constexpr uint64_t kMaxDeflateRatio = 1032;

}  // namespace cli

#endif  // VASCO_GPU_TOOLS_READ_AHEAD_H
