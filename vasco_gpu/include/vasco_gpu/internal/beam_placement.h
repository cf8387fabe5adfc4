// beam_placement.h — where every beam of a batch starts and ends, in grid
// cells, computed by the oracle's own code (oracle.h) on the host: scans are
// placed in order (the first fixes the start pose), end cells in parallel
// over scans with the oracle's angle accumulation. The exact backends that
// reorder the work (cpu_threads, the CUDA exact mode) start from this, so
// their beams are the oracle's bit for bit (DESIGN §2.2).
#ifndef VASCO_GPU_BEAM_PLACEMENT_H
#define VASCO_GPU_BEAM_PLACEMENT_H

#include <cstdint>
#include <memory>
#include <vector>

#include "vasco_gpu/grid.h"
#include "vasco_gpu/internal/oracle.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/internal/placed_beam.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

struct PlacedBeams {
  size_t first_scan = 0;                  // starts[i] is scan first_scan + i
  std::vector<oracle::ScanStart> starts;  // per placed scan
  std::vector<PlacedBeam> beams;          // used beams only, in (scan, beam) order
  uint64_t skipped = 0;                   // beams not used (>= 50 m, NaN, +inf)
};

// Places scans [first, last) (all by default); scan 0 of the batch fixes the
// start pose, as CARMEN's first update call does.
std::vector<oracle::ScanStart> place_scans(const ScanBatch &batch, const GridGeometry &geo, size_t first = 0,
                                           size_t last = SIZE_MAX);

// Where each placed scan's used beams go: the starts of scans [first, last)
// and, per placed scan, the number of used beams before it. Counted on
// `threads` cores (<= 0: all).
struct BeamLayout {
  size_t first_scan = 0;
  std::vector<oracle::ScanStart> starts;  // per placed scan
  std::vector<uint64_t> used_before;      // per placed scan, and the total last
  uint64_t skipped = 0;
  uint64_t used() const { return used_before.empty() ? 0 : used_before.back(); }
};
BeamLayout lay_out_beams(const ScanBatch &batch, const GridGeometry &geo, int threads, size_t first = 0,
                         size_t last = SIZE_MAX);

// Writes the used beams of every laid-out scan to out[0 .. layout.used()),
// on `threads` cores. `out` is the caller's: a vector, or a GPU backend's
// pinned staging buffer.
void place_laid_out_beams(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
                          const BeamLayout &layout, int threads, PlacedBeam *out);

// One scan's used beams at a time, for a backend that adds each scan's beams
// as it places them (they stay in cache, and a log's worth of PlacedBeam is
// never stored): the same end cells as place_beams, with its caches.
class BeamEnds;
class ScanBeamPlacer {
 public:
  ScanBeamPlacer();
  ~ScanBeamPlacer();
  ScanBeamPlacer(const ScanBeamPlacer &) = delete;
  ScanBeamPlacer &operator=(const ScanBeamPlacer &) = delete;
  // Scan s's used beams, placed from `start` (place_scans'), written from
  // out[0] on (batch.beams_in(s) at most) with `scan_index` as their scan;
  // returns how many.
  size_t place(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
               const oracle::ScanStart &start, size_t s, uint32_t scan_index, PlacedBeam *out);

 private:
  std::unique_ptr<BeamEnds> ends_;
};

// The starts of scans [first, last) (all scans by default) and the end cells
// of their used beams; threads <= 0: all cores. Throws std::runtime_error
// past 2^32 used beams.
PlacedBeams place_beams(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
                        int threads, size_t first = 0, size_t last = SIZE_MAX);

}  // namespace vasco

#endif  // VASCO_GPU_BEAM_PLACEMENT_H
