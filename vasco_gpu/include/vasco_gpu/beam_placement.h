// beam_placement.h — where every beam of a batch starts and ends, in grid
// cells, computed by the oracle's own code (oracle.h) on the host: scans are
// placed in order (the first fixes the start pose), end cells in parallel
// over scans with the oracle's angle accumulation. The exact backends that
// reorder the work (cpu_threads, the CUDA exact mode) start from this, so
// their beams are the oracle's bit for bit (DESIGN §2.2).
#ifndef VASCO_GPU_BEAM_PLACEMENT_H
#define VASCO_GPU_BEAM_PLACEMENT_H

#include <cstdint>
#include <vector>

#include "vasco_gpu/grid.h"
#include "vasco_gpu/oracle.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

// A used beam (range < 50 m): 16 bytes, the layout the CUDA exact mode uploads.
struct PlacedBeam {
  int x2, y2;      // end cell (oracle::beam_end)
  uint32_t scan;   // its scan; the start cell is starts[scan].x1, .y1
  float range;
};

struct PlacedBeams {
  std::vector<oracle::ScanStart> starts;  // per scan
  std::vector<PlacedBeam> beams;          // used beams only, in (scan, beam) order
  uint64_t skipped = 0;                   // beams not used (>= 50 m, NaN, +inf)
};

// Places every scan, in order (the first call fixes the start pose).
std::vector<oracle::ScanStart> place_scans(const ScanBatch &batch, const GridGeometry &geo);

// Every scan's start, and the end cells of the used beams of scans [first,
// last) (all scans by default); threads <= 0: all cores. Throws
// std::runtime_error past 2^32 used beams.
PlacedBeams place_beams(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
                        int threads, size_t first = 0, size_t last = SIZE_MAX);

}  // namespace vasco

#endif  // VASCO_GPU_BEAM_PLACEMENT_H
