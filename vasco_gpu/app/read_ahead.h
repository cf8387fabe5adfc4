// read_ahead.h — which inputs of a batch are read ahead of its mappers.
//
// Reading (inflate + parse) runs on the pool while the mappers map; how far
// it may run ahead decides whether the pool idles while a GPU backend starts
// (0.2-0.3 s, up to a third of a 200-log batch) and how much memory parsed inputs
// hold. Inputs are let through in order while all of these hold: fewer than
// `in_flight` reads are under way (the pool runs only so many at once);
// fewer than `most` inputs are read or being read and not yet taken by a
// mapper; and the bytes of the inputs read and not yet released, plus what
// each read under way may come to hold, stay within `budget`. A read under
// way counts from the moment it is let through (before any of its size is
// known) at the larger of its input's estimate (parsed_bytes_estimate: what
// its file may parse to) and the mean size read so far; once it ends, at its
// size. The next input a mapper will take is let through whatever its size,
// so a batch of inputs larger than the budget still runs, one ahead.
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
  ReadAhead(size_t inputs, size_t in_flight, size_t most, uint64_t budget, std::vector<uint64_t> estimates = {});

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
  // What the reads under way are counted at.
  uint64_t reserved_bytes() const { return reserved_; }

 private:
  bool may_admit(size_t i) const;
  uint64_t reservation(size_t i) const;

  const size_t in_flight_max_, most_;
  const uint64_t budget_;
  std::vector<uint64_t> estimates_;  // per input, as given
  std::vector<uint64_t> bytes_;      // per input: held until released
  std::vector<uint64_t> reserved_for_;  // per input: counted while its read is under way
  size_t next_ = 0;                  // the next input to let through
  size_t taken_ = 0;                 // inputs taken by mappers
  size_t in_flight_ = 0;             // let through, read not yet ended
  uint64_t held_ = 0;                // bytes of inputs read and not released
  uint64_t reserved_ = 0;            // the reads under way's reservations
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
