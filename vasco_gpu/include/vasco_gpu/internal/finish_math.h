// finish_math.h — CARMEN 0.7.4's finish of an evidence grid (DESIGN §2 step
// 7), written once and compiled into the CPU finish (grid.cc) and the GPU's
// (src/cuda/finish_kernels.cu): the mean of each ds x ds block's known cells,
// summed in double in CARMEN's order; the bounding box of the known blocks,
// from CARMEN's start values; the crop to that box plus the border, clamped
// to the block grid; the new size max - min (no +1) at resolution * ds.
//
// Pure functions of their arguments, as in egrid_math.h. Box arithmetic is
// 64-bit: CARMEN's int arithmetic overflows for a border near INT_MAX (max +
// border), where ours clamps to the grid as a large border should.
#ifndef VASCO_GPU_FINISH_MATH_H
#define VASCO_GPU_FINISH_MATH_H

#include <cstdint>
#include <string>

#include "carmen_compat/host_device.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/grid.h"

namespace vasco {
namespace finish {

// The downsampled grid: size / ds blocks per axis (CARMEN drops the rest).
struct Blocks {
  int nx = 0, ny = 0;
  VG_HD int64_t count() const { return static_cast<int64_t>(nx) * ny; }
};
VG_HD Blocks blocks_of(int size_x, int size_y, int ds) { return {size_x / ds, size_y / ds}; }

// A block's value: the mean of its known cells, -1 when none is known.
struct BlockMean {
  float value = -1.0f;
  bool known = false;
};

// Block (bx, by) of a grid whose cell (i, j) is cell_at(i * size_y + j), a
// probability or -1 (unknown). Summed in double, i outer and j inner as
// CARMEN does, divided once: the same float wherever it runs (an add and a
// divide, nothing for a compiler to fuse; double division is IEEE on the GPU).
template <class CellAt>
VG_HD BlockMean block_mean(const CellAt &cell_at, int size_y, int ds, int bx, int by) {
  double sum = 0;
  int count = 0;
  for (int i = bx * ds; i < (bx + 1) * ds; ++i) {
    const int64_t column = static_cast<int64_t>(i) * size_y;
    for (int j = by * ds; j < (by + 1) * ds; ++j) {
      const float v = cell_at(column + j);
      if (v != -1.0f) {
        sum += v;
        ++count;
      }
    }
  }
  BlockMean m;
  if (count > 0) {
    m.value = static_cast<float>(sum / static_cast<double>(count));
    m.known = true;
  }
  return m;
}

// The bounding box of the known blocks, inclusive; empty while none is known.
struct KnownBox {
  int min_x = INT32_MAX, max_x = -1, min_y = INT32_MAX, max_y = -1;
};
VG_HD void widen(KnownBox &box, int bx, int by) {
  if (bx < box.min_x) box.min_x = bx;
  if (bx > box.max_x) box.max_x = bx;
  if (by < box.min_y) box.min_y = by;
  if (by > box.max_y) box.max_y = by;
}

// The finished map's window of the block grid: [min, min + size) per axis.
struct Crop {
  int min_x = 0, min_y = 0;
  int size_x = 0, size_y = 0;
  VG_HD int64_t count() const { return static_cast<int64_t>(size_x) * size_y; }
};

// One axis of the crop: CARMEN starts the box at (n - border - 1, border),
// widens it by the known blocks, moves each side out by the border, clamps
// to [0, n - 1] and keeps max - min (at least 0).
VG_HD void crop_axis(int known_min, int known_max, int n, int border, int *min_out, int *size_out) {
  int64_t lo = static_cast<int64_t>(n) - border - 1, hi = border;
  if (known_min < lo) lo = known_min;
  if (known_max > hi) hi = known_max;
  lo -= border;
  hi += border;
  if (lo < 0) lo = 0;
  if (hi > static_cast<int64_t>(n) - 1) hi = static_cast<int64_t>(n) - 1;
  *min_out = static_cast<int>(lo);  // in [0, n - 1], or 0
  *size_out = hi > lo ? static_cast<int>(hi - lo) : 0;
}

VG_HD Crop crop_of(const KnownBox &known, const Blocks &blocks, int border) {
  Crop c;
  crop_axis(known.min_x, known.max_x, blocks.nx, border, &c.min_x, &c.size_x);
  crop_axis(known.min_y, known.max_y, blocks.ny, border, &c.min_y, &c.size_y);
  return c;
}

// Where cell (x, y) of the finished map (x-major, cells[x * size_y + y])
// lies in the block array (blocks[bx * ny + by]).
VG_HD int64_t cropped_block(const Crop &crop, const Blocks &blocks, int x, int y) {
  return static_cast<int64_t>(x + crop.min_x) * blocks.ny + (y + crop.min_y);
}

// Refuses what CARMEN's finish cannot mean: a block under one cell, a
// negative border (host only: a usage error of the caller).
inline void check_arguments(int downsample, int border) {
  if (downsample < 1)
    throw Error(ErrorCode::Usage, "finish: downsample " + std::to_string(downsample) + " must be at least 1");
  if (border < 0) throw Error(ErrorCode::Usage, "finish: border " + std::to_string(border) + " must not be negative");
}

// The finished map of a crop, its cells not yet filled (host only): a
// block is ds cells wide.
inline FinishedMap finished_frame(const Crop &crop, double resolution, int ds) {
  FinishedMap m;
  m.downsample = ds;
  m.resolution = resolution * ds;
  m.min_x = crop.min_x;
  m.min_y = crop.min_y;
  m.size_x = crop.size_x;
  m.size_y = crop.size_y;
  return m;
}

}  // namespace finish
}  // namespace vasco

#endif  // VASCO_GPU_FINISH_MATH_H
