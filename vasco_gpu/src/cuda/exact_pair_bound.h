// exact_pair_bound.h — CUDA exact mode's host bound on the (tile, beam)
// pairs of a placed batch, so that the pair arrays are sized before the
// launch and no apply waits for the real count.
#ifndef VASCO_GPU_SRC_CUDA_EXACT_PAIR_BOUND_H
#define VASCO_GPU_SRC_CUDA_EXACT_PAIR_BOUND_H

#include <cstddef>
#include <cstdint>
#include <vector>

#include "vasco_gpu/internal/oracle.h"
#include "vasco_gpu/internal/placed_beam.h"

namespace vasco {
namespace cuda_host {

// The sum over the beams of the tiles each beam's walk can enter, on all cores.
uint64_t exact_pair_bound(const PlacedBeam *beams, size_t n, const std::vector<oracle::ScanStart> &starts,
                          int table_size);

// Beams per exact-mode launch such that the pairs, at most 2 * (table_size /
// kTile + 2) per beam (a monotone walk of table_size cells enters no more
// tiles), stay below 2^32 (they are counted in 32 bits).
uint64_t exact_beams_per_launch(int table_size);

}  // namespace cuda_host
}  // namespace vasco

#endif  // VASCO_GPU_SRC_CUDA_EXACT_PAIR_BOUND_H
