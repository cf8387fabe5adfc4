// egrid_kernels.h — what the CUDA backend's host side (vasco_gpu/src/cuda/)
// calls. Plain C++: no CUDA syntax, so host code compiled by the C++
// compiler can include it. All pointers are device pointers; every launcher
// enqueues on `stream` and checks the launch.
#ifndef VASCO_CUDA_EGRID_KERNELS_H
#define VASCO_CUDA_EGRID_KERNELS_H

#include <cuda_runtime.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "vasco_gpu/internal/egrid_math.h"
#include "carmen_compat/occupancy_value.h"
#include "vasco_gpu/internal/finish_math.h"
#include "vasco_gpu/internal/placed_beam.h"

namespace vasco {
namespace cuda {

// The sensor model and the grid as the kernels read them, in their mode's
// precision: double in exact mode (the oracle's values), float in float mode.
template <class Real>
struct KernelModel {
  egrid::SensorModel<Real> sensor;
  Real resolution, wall;
  int table_size;      // (int)(max_range / resolution)
  int size_x, size_y;  // grid size in cells
  // The grid holds columns [x_begin, x_begin + size_x) of the frame the
  // scans are placed in (a band of a split render; 0 for a whole grid).
  int x_begin;
  // Exact mode: within max_sure_range the evidence is occ or emp itself, so
  // cells with i*i + j*j < n_sure take one of these two factors, no table.
  int n_sure;
  double factor_free_near, factor_occ_near;
  // Float mode: log(prior / (1 - prior)).
  Real logodds_prior;
};

// ---------------------------------------------------------------------------
// Exact mode: bit-identical to cpu_double.
// ---------------------------------------------------------------------------

// A scan's start cell; beams (vasco::PlacedBeam, only the used ones) name
// their scan's by index.
struct StartCell {
  int x1, y1;
};

// A beam's walk, in the form one thread per cell needs to test membership
// without division (see egrid_math.h line_step_of_cell). 48 bytes.
struct LineRec {
  int x1, y1;       // start cell, grid coordinates
  int sx1, sy1;     // start in the swapped/flipped frame (major, minor)
  int two_a, two_b; // 2|major delta| (1 when it is 0) and 2|minor delta|
  int bias;         // |major delta| - (inc < 0), or 0 when the delta is 0
  int k_max;        // last step that can update a cell: min(|major delta|, table_size - 1)
  int flags;        // kSteep | kFlipped | kBackward | kDegenerate
  float range;
  int x2, y2;       // end cell (for the sequential fall-back of degenerate lines)
  int free_below;   // a cell is free (distance < range) iff i*i + j*j < free_below (tables only)
};
constexpr int kSteep = 1, kFlipped = 2, kBackward = 4, kDegenerate = 8;
// Exact mode works on kTile x kTile cell tiles, a block of kTile^2 threads
// each. Small tiles keep the longest tile lists (where the robot passed
// often) short: a tile's blocks run its list sequentially, so the longest list
// bounds the kernel.
constexpr int kTile = 8;
// The most tiles an exact-mode grid may have: tile ids are int in the kernels
// and uint32 in the pairs (kNoTile, 2^32 - 1, sorts after every real one,
// and the sort's tile_bits stay <= 31), and the tiles kernel runs a block per
// tile (gridDim.x <= 2^31 - 1). 2^31 - 1 tiles are 2^37 cells, 512 GiB of
// floats: beyond every GPU's memory, but refused by name (the host's
// reserve_grid) rather than left to wrap.
constexpr size_t kMaxExactTiles = 0x7fffffff;

// Scratch sizes for the CUB calls of exact mode.
size_t exact_scan_temp_bytes(size_t num_beams);
size_t exact_sort_temp_bytes(size_t num_pairs);

// Exact mode's tables, computed on the device with the oracle's operations,
// for table_size <= kMaxExactTable: the odds factors (free, occupied) per
// (i, j), table_size^2 of them, and per i the first j whose distance reaches
// max_range (table_size entries).
constexpr int kMaxExactTable = 2048;
void launch_exact_tables(const KernelModel<double> &m, double2 *factors, int *reach, cudaStream_t stream);

// The beams' placement on the device (exact_placement.cu): what the host
// does with the oracle's code (beam_placement.cc), from a record per scan
// and the device's copy of the ranges. A scan's beam angles are the
// oracle's repeated additions (oracle::SteppedAngles), a warp per scan. A
// beam's end cell is (int)(l + (range + wall) * cos(angle) / resolution) per
// axis, computed with CUDA's cos and sin, which are within 2 ulp of the true
// value as glibc's are within 1: where egrid::far_from_integers says the
// truncation is the oracle's, it is kept; elsewhere (a few beams in 10^7,
// and non-finite values or those past 2^30) the beam is listed as unsure and
// the host places it with the oracle's own code (launch_exact_fix).
struct ExactScan {
  double lx, ly;        // laser position in cells (oracle::scan_start)
  double angle0, step;  // beam 0's angle (theta + first) and the step added after each beam
  uint32_t beam_begin;  // first beam, counted from the launch's first
  int beam_count;
  int x1, y1;           // start cell
};
struct UnsureBeam {
  uint32_t slot;  // its PlacedBeam's index
  uint32_t scan;  // counted from the launch's first
  double angle;
  float range;
};
struct BeamFix {
  uint32_t slot;
  int x2, y2;
};
struct PlacementModel {
  double resolution, wall;  // the frame's cell and the parameters' wall_size
  int table_size;
};

// Per beam: 1 where it is used (egrid::is_beam_used), 0 else, and a 0 after
// the last (num_beams + 1 entries, for exact_scan).
void launch_exact_used(const float *ranges, size_t num_beams, uint32_t *used, cudaStream_t stream);
// Per used beam i of each scan (a warp per scan, its beams' angles summed
// as the oracle sums them): its PlacedBeam at beams[slots[i]] (slots:
// exact_scan of `used`). counters[0] += the beams' tile bounds (exact_tile_bound.h; the
// box bound for an unsure beam), counters[1] += the unsure beams, the first
// `unsure_capacity` of which are listed in `unsure` (their end cells left
// for launch_exact_fix).
void launch_exact_place(const PlacementModel &m, const ExactScan *scans, int num_scans, const float *ranges,
                        const uint32_t *slots, PlacedBeam *beams, UnsureBeam *unsure, uint32_t unsure_capacity,
                        unsigned long long *counters, cudaStream_t stream);
// The host's end cells of the unsure beams.
void launch_exact_fix(const BeamFix *fixes, size_t n, PlacedBeam *beams, cudaStream_t stream);

// Per beam: builds its LineRec and counts the tiles its walk passes through.
void launch_exact_lines(const KernelModel<double> &m, const PlacedBeam *beams, const StartCell *starts,
                        size_t num_beams, LineRec *lines, uint32_t *tile_counts,
                        cudaStream_t stream);

// Exclusive prefix sum of the per-beam tile counts (num_beams + 1 entries out).
void exact_scan(const uint32_t *counts, uint32_t *offsets, size_t num_beams, void *temp,
                size_t temp_bytes, cudaStream_t stream);

// Per beam: writes (tile, beam) pairs at its offset, in walk order, into
// arrays of `capacity` pairs: a bound the host computed (exact_pair_bound), so
// that no render waits for the real count. The slots after the real pairs
// hold kNoTile. If the real count passed the capacity nothing is written and
// *overflow is incremented.
constexpr uint32_t kNoTile = 0xffffffffu;
void launch_exact_pairs(const KernelModel<double> &m, const LineRec *lines, const uint32_t *offsets,
                        size_t num_beams, size_t capacity, uint32_t *pair_tile, uint32_t *pair_beam,
                        unsigned long long *overflow, cudaStream_t stream);

// The key bits a radix sort of keys up to n looks at: the fewest b (1 to 32)
// with 2^b > n.
inline int key_bits_above(uint64_t n) {
  int b = 1;
  while (b < 32 && (uint64_t(1) << b) <= n) ++b;
  return b;
}

// Stable sort of the pairs by tile: each tile's beams stay in (scan, beam)
// order. tile_bits must leave kNoTile's low bits above every real tile
// (key_bits_above(num_tiles)).
void exact_sort(const uint32_t *tile_in, uint32_t *tile_out, const uint32_t *beam_in,
                uint32_t *beam_out, size_t num_pairs, int tile_bits, void *temp,
                size_t temp_bytes, cudaStream_t stream);

// Each tile's slice [begin, end) of the sorted pairs (kNoTile ignored).
void launch_exact_tile_ranges(const uint32_t *sorted_tile, size_t num_pairs, uint32_t *tile_begin,
                              uint32_t *tile_end, size_t num_tiles, cudaStream_t stream);

// The order in which to run the tiles: longest list first (so that the
// longest ones do not start last and make the tail), as tile ids in `order`,
// and in *heavy_count how many of the first run as heavy tiles (a block of
// their own; see launch_exact_tiles). A list holds a beam at most once (a
// straight walk never re-enters a tile), so its length is at most num_beams,
// and the sort looks at that many bits alone. Scratch: three arrays of
// num_tiles and exact_order_temp_bytes(num_tiles) bytes.
size_t exact_order_temp_bytes(size_t num_tiles);
void exact_tile_order(const uint32_t *tile_begin, const uint32_t *tile_end, size_t num_tiles, size_t num_beams,
                      uint32_t *order, uint32_t *scratch_keys, uint32_t *scratch_keys_out,
                      uint32_t *scratch_ids, uint32_t *heavy_count, void *temp, size_t temp_bytes,
                      cudaStream_t stream);

// The streams of the tiles kernels: the light tiles run on `main`, the
// heavy ones on `side` (of the highest priority, so that its blocks start
// first) at the same time; `fork` and `join` (events) order
// `side` after what `main` queued before and `main`'s later work after it.
struct TileStreams {
  cudaStream_t main, side;
  cudaEvent_t fork, join;
};

// One thread per cell of each tile, in the order of exact_tile_order: a
// heavy tile (its first *heavy_count) in a block of 256 threads, the others
// in blocks of 64. Applies every beam of the tile's list, in order, to the
// thread's own cell, and writes the final grid (x-major floats, -1 unknown).
// The tables are all null above kMaxExactTable (distances on the fly).
void launch_exact_tiles(const KernelModel<double> &m, const LineRec *lines, const uint32_t *sorted_beam,
                        const uint32_t *order, const uint32_t *tile_begin, const uint32_t *tile_end,
                        const uint32_t *heavy_count, const double2 *factors, const int *reach, float *grid,
                        unsigned long long *cell_updates, const TileStreams &streams);

// ---------------------------------------------------------------------------
// Float mode: single precision, all scans fused into one launch.
// ---------------------------------------------------------------------------
struct FloatScan {
  float lx, ly;        // laser position in cells (from the host's double placement)
  float theta;         // heading in the grid frame
  int x1, y1;          // start cell
  float first, step;   // beam angles: theta + first + i * step
  uint32_t beam_begin; // first beam in the range array
  int beam_count;
};

// Float mode accumulates each cell's log-odds evidence in a 64-bit integer,
// with integer atomics: integer addition is associative, so the sum, and
// the map, are the same bytes on every run and every GPU of the same build
// (float atomics added in a different order each run). An update of log-odds
// increment x adds (q << kFixedCountBits) + 1, q = round(x * 2^kFixedFracBits):
//  - the low bits count the updates, so 0 means "never updated"; the count
//    carries into the sum only after 2^16 updates of one cell, adding 2^-24
//    log-odds per carry, and a cell reads as never updated only if such a
//    count also lands on an exactly opposite sum;
//  - the sum holds +-2^23 log-odds in steps of 2^-24: a step is 6e-8, below
//    the float rounding of x itself (|x| ~ 0.2 has a float ulp of 1.5e-8 and
//    __logf's error is larger), and the host refuses a render whose beams
//    could push any cell past +-2^22 (kFixedLimit: cells get one update per
//    beam at most).
// What the quantization costs against CARMEN: nothing measurable. On all 27
// public golden cases (golden_check --paths cuda_exact,cuda_float, H200,
// 2026-12-01), float atomics before and fixed point after give the same
// agreement table (max |dp|, cells with |dp| > 0.1, known/unknown status
// differences, to the cell) except the occupied/free class agreement of two
// cases: edge_cases/vasco_default_raw 99.9942 -> 99.9937 %, freiburg-campus/
// vasco_default_raw_first100 99.9978 -> 99.9977 % (and "before" was one draw
// of an order that changed every run).
constexpr int kFixedCountBits = 16, kFixedFracBits = 24;
constexpr double kFixedLimit = 4194304.0;  // 2^22 log-odds

// Float mode's increments per cell offset (i, j) from the start, for tables
// of at most kMaxFloatTable entries per axis (32 MiB): {free, occupied} in
// fixed-point units, or kFloatStops where the beam stops (d >= max_range).
// They are the values an update computes in full, so a lookup changes no bit.
constexpr int kMaxFloatTable = 2048;
constexpr int kFloatStops = INT32_MIN;
void launch_float_tables(const KernelModel<float> &m, int2 *increments, cudaStream_t stream);

// Sets every cell to 0, float mode's "never updated".
void launch_float_clear(unsigned long long *sums, size_t num_cells, cudaStream_t stream);

// Whether this build holds code the current device can run (machine code for
// its architecture, or PTX the driver can compile for it); `why` otherwise.
bool kernels_runnable_on_current_device(std::string *why);

// Every cell to `value` (exact mode: a fresh grid is all kUnknown).
void launch_fill(float *cells, size_t num_cells, float value, cudaStream_t stream);

// Probabilities (-1 unknown) to float mode's fixed-point sums, for
// continuing a grid mapped earlier (0 and 1 saturate at +-2^20 log-odds).
void launch_float_from_prob(const KernelModel<float> &m, const float *probs, unsigned long long *sums,
                            size_t num_cells, cudaStream_t stream);

// Adds every beam's log-odds evidence to `sums` (integer atomics: no update
// is lost, none depends on the order). `increments`: launch_float_tables'
// tables, or null to compute every update in full. `across`: null, or
// scratch of size_x * size_y cells for the beams that step along x (a
// y-major accumulator, so that a warp's adds are coalesced), cleared first
// and added to `sums` at the end: the same sums. counters: beams used,
// beams skipped, cell updates.
void launch_float_map(const KernelModel<float> &m, const int2 *increments, const FloatScan *scans, int num_scans,
                      const float *ranges, unsigned long long *sums, unsigned long long *across,
                      unsigned long long *counters, cudaStream_t stream);

// The floors of launch_float_map's accumulation, for mapping_bench's
// ablation only (`sums` comes out wrong): the same walk with every update
// added to a register (no memory at all: the walk's own cost), or to a
// 64 x 64-cell tile in shared memory at the cell's position modulo 64, never
// flushed (what any per-tile layout pays at least, before binning the beams
// by tile and flushing the tiles).
enum class FloatFloor { Registers, SharedTile };
void launch_float_map_floor(FloatFloor floor, const KernelModel<float> &m, const int2 *increments,
                            const FloatScan *scans, int num_scans, const float *ranges, unsigned long long *sums,
                            unsigned long long *counters, cudaStream_t stream);

// Float log-odds sums (the paper's kernels, bench/experiments) ->
// probability, in place; cells never updated become -1: those still -0.0f,
// or, when `touched` is given, those whose flag is 0.
void launch_float_finalize(const KernelModel<float> &m, float *grid_logodds, const uint8_t *touched,
                           size_t num_cells, cudaStream_t stream);

// ---------------------------------------------------------------------------
// CARMEN's finish on the device (finish_kernels.cu), with finish_math.h's
// functions: block means, the known bounding box, the crop. Only the
// finished map then crosses the bus.
// ---------------------------------------------------------------------------

// The grid's cells: probabilities (exact mode) or, when `sums` is set, float
// mode's fixed-point sums, read as prob_of_fixed does.
struct GridCells {
  const float *probs = nullptr;
  const unsigned long long *sums = nullptr;
  float logodds_prior = 0;
};

// blocks[bx * ny + by] for the block grid of finish::blocks_of(size_x,
// size_y, ds), and `known` widened by every known block (the caller sets it
// to an empty finish::KnownBox first).
void launch_finish_blocks(GridCells grid, int size_x, int size_y, int ds, float *blocks, finish::KnownBox *known,
                          cudaStream_t stream);

// out[x * crop.size_y + y] = blocks[finish::cropped_block(crop, blocks_grid, x, y)].
void launch_crop(const float *blocks, finish::Blocks blocks_grid, finish::Crop crop, float *out,
                 cudaStream_t stream);

// The crop as nav_msgs/OccupancyGrid data, row-major from the lower-left
// cell: out[y * crop.size_x + x] = occupancy_value(values, the crop's (x, y))
// (carmen_compat/occupancy_value.h, the host conversion's own rule).
void launch_occupancy_crop(const float *blocks, finish::Blocks blocks_grid, finish::Crop crop,
                           carmen::OccupancyValues values, int8_t *out, cudaStream_t stream);

// A window of the grid as probabilities: out[x * height + y].
void launch_read_window(GridCells grid, int size_y, int x0, int y0, int width, int height, float *out,
                        cudaStream_t stream);

// Probabilities from a float log-odds sum and from float mode's fixed-point
// sum (the expressions finalize, finish and read use, so they agree bit for
// bit).
#if defined(__CUDACC__)
__device__ __forceinline__ float prob_of_logodds(float logodds_prior, float sum) {
  if (__float_as_uint(sum) == 0x80000000u) return -1.0f;  // untouched
  // p = 1 - 1/(1 + odds), odds = exp(L): saturates to exactly 1 or 0.
  const float odds = expf(logodds_prior + sum);
  return 1.0f - 1.0f / (1.0f + odds);
}

__device__ __forceinline__ float prob_of_fixed(float logodds_prior, unsigned long long v) {
  if (v == 0) return -1.0f;  // never updated
  const long long units = static_cast<long long>(v) >> kFixedCountBits;
  const float sum = static_cast<float>(units) * (1.0f / static_cast<float>(1 << kFixedFracBits));
  const float odds = expf(logodds_prior + sum);
  return 1.0f - 1.0f / (1.0f + odds);
}
#endif

}  // namespace cuda
}  // namespace vasco

#endif  // VASCO_CUDA_EGRID_KERNELS_H
