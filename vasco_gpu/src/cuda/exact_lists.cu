// Exact mode's lists (exact_cells.cuh, steps 2 and 3): each placed beam's
// line and the tiles its walk passes through, as (tile, beam) pairs written
// in beam order, then sorted by tile (stably: each tile's beams stay in
// (scan, beam) order) and each tile's range of the sorted list.

#include <cub/cub.cuh>

#include "cuda_check.h"
#include "egrid_kernels.h"
#include "exact_cells.cuh"
#include "launch_shape.cuh"
#include "line_rec.cuh"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace cuda {
namespace {

// A closed-form line's walk through the grid's tiles, a column of tiles at a
// time: along the major axis the k of a column of tiles (kTile steps) is an
// interval, and over it the minor coordinate moves monotonically by at most
// one cell a step, so the walk visits exactly the tiles between the minor
// coordinates at the interval's ends (both clipped to the grid): one or two.
// Columns are numbered from the start; each can be taken on its own, so a
// warp can take a line's columns a lane each (pairs_kernel).
struct TileColumns {
  bool steep, backward, flipped;
  int maj_lo, min_lo, size_min, tiles_y;
  int k_lo, k_hi;  // the steps whose major coordinate is inside the grid (none when k_lo > k_hi)
  int k_end0;      // the last step of the first column

  __device__ TileColumns(const LineRec &L, const KernelModel<double> &m) {
    steep = L.flags & kSteep;
    backward = L.flags & kBackward;
    flipped = L.flags & kFlipped;
    tiles_y = (m.size_y + kTile - 1) / kTile;
    // The grid's range of each coordinate: x from x_begin, y from 0.
    maj_lo = steep ? 0 : m.x_begin;
    min_lo = steep ? m.x_begin : 0;
    const int size_maj = steep ? m.size_y : m.size_x;
    size_min = steep ? m.size_x : m.size_y;
    // Steps whose major coordinate (sx1 +- k) is inside the grid (in 64 bits:
    // a start cell can be anywhere an int reaches).
    const int64_t to_lo = static_cast<int64_t>(L.sx1) - maj_lo, to_hi = maj_lo + int64_t(size_maj) - 1 - L.sx1;
    const int64_t k_max = L.k_max, lo = backward ? -to_hi : -to_lo, hi = backward ? to_lo : to_hi;
    k_lo = static_cast<int>(lo < 0 ? 0 : lo > k_max + 1 ? k_max + 1 : lo);
    k_hi = static_cast<int>(hi > k_max ? k_max : hi < -1 ? -1 : hi);
    k_end0 = k_hi;
    if (k_lo <= k_hi) {  // then the major coordinate at k_lo is in the grid
      const int maj = major_at(L, k_lo);
      k_end0 = min(k_hi, backward ? maj % kTile + k_lo : kTile - 1 - maj % kTile + k_lo);
    }
  }
  __device__ int count() const { return k_lo > k_hi ? 0 : 1 + (k_hi - k_end0 + kTile - 1) / kTile; }
  // The major coordinate at step k, from maj_lo (>= 0 for k in [k_lo, k_hi]).
  __device__ int major_at(const LineRec &L, int k) const { return (backward ? L.sx1 - k : L.sx1 + k) - maj_lo; }
  // The minor coordinate at step k (egrid_math.h line_cell), from min_lo.
  __device__ int minor_at(const LineRec &L, int k) const {
    const int off = (L.two_b * k + L.bias) / L.two_a;
    const int mn = backward ? L.sy1 - off : L.sy1 + off;
    return (flipped ? -mn : mn) - min_lo;
  }
  // Calls visit(tile) for the tiles of column c < count(), in walk order.
  template <class Visit>
  __device__ void visit_column(const LineRec &L, int c, Visit &&visit) const {
    // After the first column, each starts on a tile border: kTile steps, or to k_hi.
    const int k = c == 0 ? k_lo : k_end0 + 1 + (c - 1) * kTile;
    const int k_end = c == 0 ? k_end0 : min(k_hi, k + kTile - 1);
    const int tmaj = major_at(L, k) / kTile;
    const int a = minor_at(L, k), b = minor_at(L, k_end);
    if (max(a, b) < 0 || min(a, b) >= size_min) return;
    const int t_from = min(max(a, 0), size_min - 1) / kTile, t_to = min(max(b, 0), size_min - 1) / kTile;
    const int step = t_to >= t_from ? 1 : -1;
    for (int t = t_from;; t += step) {
      visit(steep ? t * tiles_y + tmaj : tmaj * tiles_y + t);
      if (t == t_to) break;
    }
  }
};

// The oracle's walker, step by step, for the rare degenerate line (see
// kClosedFormLimit): visit(tile) once per tile whose cells inside the grid it
// passes at a step that can update a cell (k <= k_max).
template <class Visit>
__device__ void for_each_tile_walked(const LineRec &L, const KernelModel<double> &m, Visit &&visit) {
  const int tiles_y = (m.size_y + kTile - 1) / kTile;
  int prev = -1;
  egrid::walk_line(L.x1, L.y1, L.x2, L.y2, L.k_max + 1, [&](int cx, int cy, int) {
    if (inside(cx, cy, m)) {
      const int t = tile_of(cx, cy, m, tiles_y);
      if (t != prev) {
        visit(t);
        prev = t;
      }
    }
    return true;
  });
}

// Calls visit(tile) once per tile whose cells inside the grid the walk visits
// at a step that can update a cell (k <= k_max). A straight line's cells are
// monotone in x and in y, so a tile, once left, is never re-entered. Closed-
// form lines go a tile column at a time: about 2 * table_size / kTile
// iterations instead of table_size.
template <class Visit>
__device__ void for_each_tile(const LineRec &L, const KernelModel<double> &m, Visit visit) {
  if (L.k_max < 0) return;
  if (L.flags & kDegenerate) {
    for_each_tile_walked(L, m, visit);
    return;
  }
  const TileColumns columns(L, m);
  for (int c = 0, n = columns.count(); c < n; ++c) columns.visit_column(L, c, visit);
}

__global__ void lines_kernel(KernelModel<double> m, const PlacedBeam *beams, const StartCell *starts,
                             size_t n, LineRec *lines, uint32_t *counts) {
  const size_t i = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const PlacedBeam b = beams[i];
  const StartCell s = starts[b.scan];
  LineRec L = make_line(s.x1, s.y1, b.x2, b.y2, b.range, m.table_size);
  if (m.table_size <= kMaxExactTable) {
    const int64_t n_max = 2 * static_cast<int64_t>(m.table_size) * m.table_size;
    L.free_below = static_cast<int>(egrid::first_square_not_below(b.range, m.resolution, n_max));
  }
  lines[i] = L;
  uint32_t c = 0;
  for_each_tile(L, m, [&](int) { ++c; });
  counts[i] = c;
}

// Each group of kPairLanes lanes writes one beam's (tile, beam) pairs at its
// offset, a tile column a lane: the group's pairs are consecutive, so its
// stores are too (a thread per beam, each writing its own run, scattered
// every store of a warp over 32 lines: 0.99 ms of fr079's 5.8 ms). A beam
// whose pairs do not come to what lines_kernel counted (a bug) is reported
// like an overflow, never written past its run.
constexpr int kPairLanes = 8;

__global__ void pairs_kernel(KernelModel<double> m, const LineRec *lines, const uint32_t *offsets, size_t n,
                             size_t capacity, uint32_t *pair_tile, uint32_t *pair_beam,
                             unsigned long long *overflow) {
  const size_t thread = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x;
  const size_t i = thread / kPairLanes;
  const int sub = static_cast<int>(thread % kPairLanes);
  if (i >= n) return;
  if (offsets[n] > capacity) {  // the host's bound was wrong: write nothing, report
    if (i == 0 && sub == 0) atomicAdd(overflow, 1ull);
    return;
  }
  const LineRec L = lines[i];
  const uint32_t begin = offsets[i], end = offsets[i + 1];
  if (L.k_max < 0) return;
  if (L.flags & kDegenerate) {
    uint32_t o = begin;
    if (sub == 0) {
      for_each_tile_walked(L, m, [&](int t) {
        if (o < end) {
          pair_tile[o] = static_cast<uint32_t>(t);
          pair_beam[o] = static_cast<uint32_t>(i);
        }
        ++o;
      });
      if (o != end) atomicAdd(overflow, 1ull);
    }
    return;
  }
  const unsigned group = ((1u << kPairLanes) - 1) << ((threadIdx.x & 31) / kPairLanes * kPairLanes);
  const TileColumns columns(L, m);
  const int n_columns = columns.count();
  uint32_t o = begin;
  for (int c0 = 0; c0 < n_columns; c0 += kPairLanes) {
    int t0 = -1, t1 = -1, got = 0;  // this lane's column: one or two tiles
    if (c0 + sub < n_columns) columns.visit_column(L, c0 + sub, [&](int t) {
      (got == 0 ? t0 : t1) = t;
      ++got;
    });
    int before = got;  // inclusive prefix over the group's lanes
    for (int d = 1; d < kPairLanes; d <<= 1) {
      const int v = __shfl_up_sync(group, before, d, kPairLanes);
      if (sub >= d) before += v;
    }
    const uint32_t at = o + before - got;
    if (got > 2 || at + got > end) {
      atomicAdd(overflow, 1ull);  // cannot happen: |minor change| < kTile within a column
    } else {
      if (got > 0) {
        pair_tile[at] = static_cast<uint32_t>(t0);
        pair_beam[at] = static_cast<uint32_t>(i);
      }
      if (got > 1) {
        pair_tile[at + 1] = static_cast<uint32_t>(t1);
        pair_beam[at + 1] = static_cast<uint32_t>(i);
      }
    }
    o += __shfl_sync(group, before, kPairLanes - 1, kPairLanes);
  }
  if (sub == 0 && o != end) atomicAdd(overflow, 1ull);
}

// kNoTile into the slots past the real pairs, [offsets[n], capacity): only
// the bound's slack (fr079: 1.06 million slots of 30.7 million), since
// pairs_kernel writes every slot before offsets[n]. Every slot when the real
// pairs passed the capacity: pairs_kernel then writes none, and the lists
// come out empty.
constexpr unsigned kPadBlocks = 256;
__global__ void pad_kernel(const uint32_t *offsets, size_t n, size_t capacity, uint32_t *pair_tile) {
  const size_t total = offsets[n];
  const size_t from = total > capacity ? 0 : total;
  const size_t stride = static_cast<size_t>(gridDim.x) * blockDim.x;
  for (size_t p = from + blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x; p < capacity; p += stride)
    pair_tile[p] = kNoTile;
}

// Tile t's slice of the sorted pairs is [first(t), first(t + 1)), first(t)
// the first position whose tile is not below t (kNoTile sorts after every
// tile): a binary search per tile boundary, num_tiles + 1 of them. (A thread
// per pair comparing each key with its neighbours read fr079's 30 million
// keys three times: 96 us on an H100, against a few us for the searches.)
__device__ __forceinline__ uint32_t first_not_below(const uint32_t *key, size_t n, uint32_t t) {
  size_t lo = 0, hi = n;
  while (lo < hi) {
    const size_t mid = lo + (hi - lo) / 2;
    if (key[mid] < t) lo = mid + 1;
    else hi = mid;
  }
  return static_cast<uint32_t>(lo);
}

__global__ void tile_ranges_kernel(const uint32_t *key, size_t n, size_t num_tiles, uint32_t *begin,
                                   uint32_t *end) {
  const size_t t = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x;
  if (t > num_tiles) return;
  const uint32_t at = first_not_below(key, n, static_cast<uint32_t>(t));
  if (t < num_tiles) begin[t] = at;
  if (t > 0) end[t - 1] = at;
}

}  // namespace

size_t exact_scan_temp_bytes(size_t num_beams) {
  size_t bytes = 0;
  VG_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, bytes, static_cast<const uint32_t *>(nullptr),
                                              static_cast<uint32_t *>(nullptr),
                                              static_cast<int64_t>(num_beams + 1)));
  return bytes;
}

size_t exact_sort_temp_bytes(size_t num_pairs) {
  size_t bytes = 0;
  VG_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(
      nullptr, bytes, static_cast<const uint32_t *>(nullptr), static_cast<uint32_t *>(nullptr),
      static_cast<const uint32_t *>(nullptr), static_cast<uint32_t *>(nullptr),
      static_cast<int64_t>(num_pairs)));
  return bytes;
}

void launch_exact_lines(const KernelModel<double> &m, const PlacedBeam *beams, const StartCell *starts,
                        size_t num_beams, LineRec *lines, uint32_t *counts, cudaStream_t stream) {
  if (num_beams == 0) return;
  lines_kernel<<<blocks_for(num_beams, 128), 128, 0, stream>>>(m, beams, starts, num_beams, lines,
                                                                counts);
  VG_CUDA_CHECK_LAUNCH();
}

void exact_scan(const uint32_t *counts, uint32_t *offsets, size_t num_beams, void *temp,
                size_t temp_bytes, cudaStream_t stream) {
  // counts has num_beams + 1 entries, the last one 0, so offsets[num_beams] is the total.
  VG_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(temp, temp_bytes, counts, offsets,
                                              static_cast<int64_t>(num_beams + 1), stream));
}

void launch_exact_pairs(const KernelModel<double> &m, const LineRec *lines, const uint32_t *offsets,
                        size_t num_beams, size_t capacity, uint32_t *pair_tile, uint32_t *pair_beam,
                        unsigned long long *overflow, cudaStream_t stream) {
  // Slots past the real pairs hold kNoTile and sort last.
  if (num_beams == 0) {
    VG_CUDA_CHECK(cudaMemsetAsync(pair_tile, 0xff, capacity * sizeof(uint32_t), stream));
    return;
  }
  pad_kernel<<<kPadBlocks, 256, 0, stream>>>(offsets, num_beams, capacity, pair_tile);
  VG_CUDA_CHECK_LAUNCH();
  pairs_kernel<<<blocks_for(num_beams * kPairLanes, 128), 128, 0, stream>>>(m, lines, offsets, num_beams, capacity,
                                                                             pair_tile, pair_beam, overflow);
  VG_CUDA_CHECK_LAUNCH();
}

void exact_sort(const uint32_t *tile_in, uint32_t *tile_out, const uint32_t *beam_in,
                uint32_t *beam_out, size_t num_pairs, int tile_bits, void *temp, size_t temp_bytes,
                cudaStream_t stream) {
  VG_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp, temp_bytes, tile_in, tile_out, beam_in,
                                                beam_out, static_cast<int64_t>(num_pairs), 0,
                                                tile_bits, stream));
}

void launch_exact_tile_ranges(const uint32_t *sorted_tile, size_t num_pairs, uint32_t *tile_begin,
                              uint32_t *tile_end, size_t num_tiles, cudaStream_t stream) {
  if (num_tiles == 0) return;
  tile_ranges_kernel<<<blocks_for(num_tiles + 1, 256), 256, 0, stream>>>(sorted_tile, num_pairs, num_tiles,
                                                                         tile_begin, tile_end);
  VG_CUDA_CHECK_LAUNCH();
}

}  // namespace cuda
}  // namespace vasco
