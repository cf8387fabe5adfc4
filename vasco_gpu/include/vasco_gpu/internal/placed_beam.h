// placed_beam.h — a used beam as the host's oracle code placed it: the one
// beam record of the placement stage, kept by cpu_threads and uploaded as is
// by the CUDA exact mode (plain C++, so the kernels' header can include it).
#ifndef VASCO_GPU_PLACED_BEAM_H
#define VASCO_GPU_PLACED_BEAM_H

#include <cstdint>

namespace vasco {

// A used beam (range < 50 m), 16 bytes, in the oracle's (scan, beam) order.
struct PlacedBeam {
  int x2, y2;      // end cell (oracle::beam_end, host libm)
  uint32_t scan;   // its scan, counted from the first placed one
  float range;     // the float range
};

}  // namespace vasco

#endif  // VASCO_GPU_PLACED_BEAM_H
