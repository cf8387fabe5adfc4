// exact_cells.cuh — what exact mode's kernels share: the grid's cells and
// its tiles (kTile x kTile cells). The kernels by job: exact_tables.cu (the
// odds-factor and reach tables), exact_lists.cu (each beam's line, its
// (tile, beam) pairs and the lists sorted by tile), exact_tiles.cu (the
// tiles in order of their lists' length, and one block per tile applying
// them); exact_placement.cu places the beams on the device.
//
// Exact mode of the CUDA backend gives a GRIDMAP bit-identical to cpu_double.
// The oracle's result for a cell is its updates applied in (scan, beam)
// order (DESIGN §2.2). We keep that order per cell without a per-cell sort:
//   1. the host places every beam with the oracle's own code (end cells);
//   2. per beam, the tiles (kTile x kTile cells) its walk passes through are
//      listed as (tile, beam) pairs, written in beam order;
//   3. a stable radix sort by tile keeps each tile's beams in beam order;
//   4. one block per tile, one thread per cell: each thread runs down its
//      tile's beam list and applies, in order, the updates of the beams that
//      cross its cell — its own cell only, so no two threads ever touch the
//      same cell and no update can be lost.
// Every double operation is the oracle's (egrid_math.h, built with
// --fmad=false), so the values match bit for bit.
#ifndef VASCO_CUDA_EXACT_CELLS_CUH
#define VASCO_CUDA_EXACT_CELLS_CUH

#include "egrid_kernels.h"

namespace vasco {
namespace cuda {
namespace {

// Whether (cx, cy) is one of the grid's cells: columns [x_begin, x_begin +
// size_x) of the frame (a band of a split render, or all of them). In
// unsigned arithmetic, defined for any cx: below size_x exactly for them.
__device__ __forceinline__ bool inside(int cx, int cy, const KernelModel<double> &m) {
  return static_cast<unsigned>(cx) - static_cast<unsigned>(m.x_begin) < static_cast<unsigned>(m.size_x) && cy >= 0 &&
         cy < m.size_y;
}

// The tile of a cell inside the grid; the grid's tiles start at x_begin.
__device__ __forceinline__ int tile_of(int cx, int cy, const KernelModel<double> &m, int tiles_y) {
  return ((cx - m.x_begin) / kTile) * tiles_y + cy / kTile;
}

}  // namespace
}  // namespace cuda
}  // namespace vasco

#endif  // VASCO_CUDA_EXACT_CELLS_CUH
