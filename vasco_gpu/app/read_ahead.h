// read_ahead.h — which inputs of a batch are read ahead of its mappers.
//
// Reading (inflate + parse) runs on the pool while the mappers map; how far
// it may run ahead decides whether the pool idles while a GPU backend starts
// (0.2-0.3 s, up to a third of a 200-log batch) and how much memory parsed inputs
// hold. Inputs are let through in order while all of these hold: fewer than
// `in_flight` reads are under way (the pool runs only so many at once);
// fewer than `most` inputs are read or being read and not yet taken by a
// mapper; and the bytes of the inputs read and not yet released, with the
// reads under way counted at the mean size read so far, stay within
// `budget`. The next input a mapper will take is let through whatever its
// size, so a batch of inputs larger than the budget still runs, one ahead.
// Not thread-safe: the batch calls it under its own lock.
#ifndef VASCO_GPU_TOOLS_READ_AHEAD_H
#define VASCO_GPU_TOOLS_READ_AHEAD_H

#include <cstddef>
#include <cstdint>
#include <vector>

namespace cli {

class ReadAhead {
 public:
  ReadAhead(size_t inputs, size_t in_flight, size_t most, uint64_t budget);

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

 private:
  bool may_admit(size_t i) const;

  const size_t in_flight_max_, most_;
  const uint64_t budget_;
  std::vector<uint64_t> bytes_;  // per input: held until released
  size_t next_ = 0;              // the next input to let through
  size_t taken_ = 0;             // inputs taken by mappers
  size_t in_flight_ = 0;         // let through, read not yet ended
  uint64_t held_ = 0;            // bytes of inputs read and not released
  uint64_t read_bytes_ = 0;      // of every read that held something
  size_t reads_ = 0;             // how many did
  bool stopped_ = false;
};

}  // namespace cli

#endif  // VASCO_GPU_TOOLS_READ_AHEAD_H
