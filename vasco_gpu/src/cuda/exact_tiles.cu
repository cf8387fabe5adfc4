// Exact mode's tiles (exact_cells.cuh, step 4): the tiles ordered by the
// length of their lists, the longest run as heavy tiles beside the light
// ones, and one block per tile whose threads each apply, in the list's
// order, the updates of the beams that cross their own cell.

#include <cub/cub.cuh>

#include "cuda_check.h"
#include "egrid_kernels.h"
#include "exact_cells.cuh"
#include "launch_shape.cuh"
#include "line_rec.cuh"
#include "warp_sum.cuh"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace cuda {
namespace {

constexpr int kTileThreads = kTile * kTile;
static_assert(kTileThreads == 64, "a tile's cells are the threads of two warps");

// A chunk of a tile's list is taken as words of 32 beams, a warp each. What
// a word's beams have in common: with tables, a beam's update of a cell
// depends on its start cell and on whether i*i + j*j < free_below, so when
// every beam of the word starts in one cell a thread can tell from these
// alone whether any of them changes its cell (drain_word).
struct WordSummary {
  int x1, y1;                          // the start cell of the word's first beam
  int min_free_below, max_free_below;  // over the word's beams
  int uniform;                         // every beam of the word starts at (x1, y1)
};

__device__ __forceinline__ int warp_min(int v) {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 800
  return __reduce_min_sync(0xffffffffu, v);
#else
  for (int offset = 16; offset > 0; offset >>= 1) v = min(v, __shfl_xor_sync(0xffffffffu, v, offset));
  return v;
#endif
}
__device__ __forceinline__ int warp_max(int v) {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 800
  return __reduce_max_sync(0xffffffffu, v);
#else
  for (int offset = 16; offset > 0; offset >>= 1) v = max(v, __shfl_xor_sync(0xffffffffu, v, offset));
  return v;
#endif
}

// Marks, for every cell of the tile, which beams of the word visit it: the
// word's beam `lane` sets bit `lane` of hit[cell * stride]. Called by a whole
// warp, lane l taking beam l (those past n mark nothing). A closed-form line
// visits one cell per step and its major coordinate is sx1 + inc*k, so only
// the (at most kTile) steps whose major coordinate lies in the tile need
// looking at; the marked set is exactly { c in tile : step_of_cell(L, c) >= 0 }.
//
// The warp goes through those steps together and merges the lanes that mark
// the same cell (__match_any_sync) into one plain write by one lane: in the
// tiles where the robot stood still every beam starts in the same cell, and
// per-lane atomics on that one word would serialise the whole warp. Only this
// warp writes its word of each cell.
__device__ void mark_word(const LineRec *sh, int n, int tx0, int ty0, unsigned *hit, int stride,
                          WordSummary *summary) {
  const int lane = threadIdx.x & 31;
  const bool mine = lane < n;
  const LineRec &L = sh[mine ? lane : 0];
  const bool closed = mine && !(L.flags & kDegenerate);
  const bool steep = L.flags & kSteep, backward = L.flags & kBackward, flipped = L.flags & kFlipped;
  const int maj0 = steep ? ty0 : tx0, min0 = steep ? tx0 : ty0;
  // Steps whose major coordinate is in [maj0, maj0 + kTile).
  int k_lo = backward ? L.sx1 - (maj0 + kTile - 1) : maj0 - L.sx1;
  const int k_hi = min(k_lo + kTile - 1, L.k_max);
  k_lo = max(k_lo, 0);
  // The walk's minor offset m(k) = (2b k + bias) / 2a (egrid_math.h
  // line_minor_offset; every operand is below 2^30, kClosedFormLimit):
  // divided once at k_lo, then carried step by step with its remainder.
  const int num0 = closed ? L.two_b * k_lo + L.bias : 0;
  int m_next = closed ? num0 / L.two_a : 0, rem = closed ? num0 - m_next * L.two_a : 0;
  for (int step = 0; step < kTile; ++step) {
    const int k = k_lo + step;
    const int m = m_next;
    rem += L.two_b;
    if (rem >= L.two_a) {
      rem -= L.two_a;
      ++m_next;
    }
    int cell = -1;
    if (closed && k <= k_hi) {
      int mn = backward ? L.sy1 - m : L.sy1 + m;
      if (flipped) mn = -mn;
      const int du = (backward ? L.sx1 - k : L.sx1 + k) - maj0, dv = mn - min0;
      if (dv >= 0 && dv < kTile) cell = steep ? dv * kTile + du : du * kTile + dv;
    }
    const unsigned peers = __match_any_sync(0xffffffffu, cell);
    if (cell >= 0 && lane == __ffs(peers) - 1) hit[cell * stride] |= peers;
    __syncwarp();
  }
  if (mine && !closed) {  // rare (see kClosedFormLimit): the oracle's walk
    egrid::walk_line(L.x1, L.y1, L.x2, L.y2, L.k_max + 1, [&](int x, int y, int) {
      const int u = egrid::wrap_sub(x, tx0), v = egrid::wrap_sub(y, ty0);  // x, y: anywhere an int reaches
      if (u >= 0 && u < kTile && v >= 0 && v < kTile) atomicOr(&hit[(u * kTile + v) * stride], 1u << lane);
      return true;
    });
  }
  if (summary == nullptr) return;
  // Lanes past n repeat the first beam, which changes neither the start nor the bounds.
  const long long start = (static_cast<long long>(L.x1) << 32) | static_cast<unsigned>(L.y1);
  int same = 0;
  __match_all_sync(0xffffffffu, start, &same);
  const int lo = warp_min(L.free_below), hi = warp_max(L.free_below);
  if (lane == 0) *summary = WordSummary{L.x1, L.y1, lo, hi, same};
}

// The (value, factor) pairs a thread has seen leave its cell's value
// unchanged. An update is a pure function of the two, so when they recur the
// arithmetic can be skipped and the result is still the oracle's, bit for
// bit. They recur a lot: a cell the robot passes thousands of times settles
// on a value its factor no longer moves (for vasco's defaults 2^-51 under
// free evidence, 1 - 2^-23 under occupied), and such cells are the longest
// chains of dependent updates in the whole grid (fr079: 11874 updates on one
// cell, of which 243 change it).
struct FixedPoints {
  unsigned value[2];
  unsigned long long factor[2];
  int known = 0;
  __device__ bool holds(float v, double f) const {
    const unsigned vb = __float_as_uint(v);
    const unsigned long long fb = static_cast<unsigned long long>(__double_as_longlong(f));
    return (known > 0 && vb == value[0] && fb == factor[0]) || (known > 1 && vb == value[1] && fb == factor[1]);
  }
  __device__ void learn(float v, double f) {
    value[1] = value[0];
    factor[1] = factor[0];
    value[0] = __float_as_uint(v);
    factor[0] = static_cast<unsigned long long>(__double_as_longlong(f));
    known = known < 2 ? known + 1 : 2;
  }
};

// What the tables say for a thread's cell seen from one start cell: whether
// a beam from there updates it, i*i + j*j, and the two odds factors. A tile
// whose list is long is one the robot stood near, so most of its beams start
// in the cell the previous one did; the thread then needs no table load (the
// latency of those loads, on the longest lists, bounded the kernel).
struct StartFactors {
  int x1 = INT_MIN, y1 = INT_MIN;
  bool update = false;
  int n = 0;
  double free = 0, occ = 0;
};

// The tables' answer for (cx, cy) from the start of L.
__device__ __forceinline__ StartFactors start_factors(const KernelModel<double> &m, const LineRec &L, int cx,
                                                      int cy, const int *reach, const double2 *factors) {
  StartFactors s;
  s.x1 = L.x1;
  s.y1 = L.y1;
  const int i = egrid::wrap_abs(egrid::wrap_sub(cx, L.x1));
  const int j = egrid::wrap_abs(egrid::wrap_sub(cy, L.y1));
  // i, j <= k <= table_size - 1: inside the tables.
  s.update = j < reach[i];  // else the oracle stops the beam here: no update
  // distance < range, and distance < max_sure_range, through i*i + j*j
  // (egrid_math.h first_square_not_below): no distance load.
  s.n = i * i + j * j;
  if (s.n < m.n_sure) {
    s.free = m.factor_free_near;
    s.occ = m.factor_occ_near;
  } else if (s.update) {
    const double2 fs = factors[static_cast<size_t>(i) * m.table_size + j];
    s.free = fs.x;
    s.occ = fs.y;
  }
  return s;
}

// The update beam L makes to (cx, cy) with the tables built: whether there
// is one (distance below max_range) and its odds factor, from `known` when L
// starts where it was computed for. Independent of the cell's value, so a
// batch of them is loaded before the dependent chain; *fresh gets the
// lookup when `known` did not serve.
__device__ __forceinline__ bool tabled_factor(const KernelModel<double> &m, const LineRec &L, int cx, int cy,
                                              const int *reach, const double2 *factors, const StartFactors &known,
                                              StartFactors *fresh, double *f) {
  if (L.x1 == known.x1 && L.y1 == known.y1) {
    *f = known.n < L.free_below ? known.free : known.occ;
    return known.update;
  }
  *fresh = start_factors(m, L, cx, cy, reach, factors);
  *f = fresh->n < L.free_below ? fresh->free : fresh->occ;
  return fresh->update;
}

// The same without tables (table_size above 2^11): everything on the fly.
__device__ __forceinline__ bool computed_factor(const KernelModel<double> &m, const LineRec &L, int cx, int cy,
                                                double *f) {
  const int i = egrid::wrap_abs(egrid::wrap_sub(cx, L.x1));
  const int j = egrid::wrap_abs(egrid::wrap_sub(cy, L.y1));
  const double d = egrid::cell_distance(i, j, m.resolution);
  // d never decreases along a walk, so the oracle's stop at the first cell
  // the model refuses is: no update where it refuses one.
  double p;
  if (!egrid::sensor_model(m.sensor, d, L.range, &p)) return false;
  *f = egrid::odds_factor(m.sensor.prior, p);
  return true;
}

// Applies the beams marked in `h` to the thread's cell, lowest bit first (the
// list's order). Factors are fetched kBatch at a time ahead of the chain of
// dependent odds updates, so their loads overlap; updates known to change
// nothing are skipped. Returns the updates made (skipped ones included).
__device__ __forceinline__ unsigned drain_hits(const KernelModel<double> &m, const LineRec *sh, unsigned long long h,
                                               int cx, int cy, const int *reach, const double2 *factors,
                                               FixedPoints *fixed, StartFactors *known, float *cell) {
  constexpr int kBatch = 4;
  unsigned count = 0;
  while (h != 0) {
    double f[kBatch];
    bool update[kBatch];
    // Lookups of one batch compare against `known` as it was at the batch's
    // start, so that their loads stay independent; the last one done
    // becomes `known` after it.
    StartFactors fresh;
#pragma unroll
    for (int u = 0; u < kBatch; ++u) {
      update[u] = false;
      f[u] = 0;
      if (h == 0) continue;
      const int e = __ffsll(static_cast<long long>(h)) - 1;
      h &= h - 1;
      update[u] = reach ? tabled_factor(m, sh[e], cx, cy, reach, factors, *known, &fresh, &f[u])
                        : computed_factor(m, sh[e], cx, cy, &f[u]);
    }
    if (fresh.x1 != INT_MIN) *known = fresh;
#pragma unroll
    for (int u = 0; u < kBatch; ++u) {
      if (!update[u]) continue;
      ++count;
      if (fixed->holds(*cell, f[u])) continue;
      const float next = egrid::odds_apply(*cell, m.sensor.prior, f[u]);
      if (__float_as_uint(next) == __float_as_uint(*cell)) fixed->learn(next, f[u]);
      *cell = next;
    }
  }
  return count;
}

// A word's hits on the thread's cell (bit e: the word's beam e), in order.
// When the word's beams all start in one cell (tables only), each of them
// multiplies the cell by the free or the occupied factor of that start, and
// where the cell is already a fixed point of every factor that can occur the
// whole word changes nothing: counted, not walked. This is the common case
// on the longest tile lists — the cells around where the robot stood, hit
// by thousands of beams from the same start after they settled.
__device__ __forceinline__ unsigned drain_word(const KernelModel<double> &m, const LineRec *sh, unsigned h,
                                               const WordSummary &s, int cx, int cy, const int *reach,
                                               const double2 *factors, FixedPoints *fixed, StartFactors *known,
                                               float *cell) {
  if (h == 0) return 0;
  if (reach != nullptr && s.uniform) {
    if (known->x1 != s.x1 || known->y1 != s.y1) *known = start_factors(m, sh[0], cx, cy, reach, factors);
    if (!known->update) return 0;  // the oracle stops these beams before the cell
    const bool all_free = known->n < s.min_free_below, all_occupied = known->n >= s.max_free_below;
    if ((all_free || fixed->holds(*cell, known->occ)) && (all_occupied || fixed->holds(*cell, known->free)))
      return __popc(h);
  }
  return drain_hits(m, sh, h, cx, cy, reach, factors, fixed, known, cell);
}

// The shared memory of one tile's run, chunks of 32 * kWords beams.
template <int kWords>
struct TileShared {
  LineRec beams[32 * kWords];
  unsigned hit[kTileThreads * kWords];  // per cell, kWords words of 32 beams
  WordSummary words[kWords];
};

// One tile's list, run by 32 * kWords threads (t = 0, 1, ...), the first 64
// of which own the tile's cells: the list is taken in chunks of 32 * kWords
// beams; the chunk's beams mark the cells they visit (a warp per word), then
// every cell's thread applies its marked beams word by word, lowest bit first
// — the list's order, which is (scan, beam) order. A warp thus runs as many
// update rounds as its busiest cell has hits, not as many as there are beams
// touching any of its cells. The next chunk's beams are fetched while this
// one is marked and applied. Returns the thread's cell updates.
template <int kWords>
__device__ unsigned run_tile(const KernelModel<double> &m, uint32_t tile, int t, TileShared<kWords> &S,
                             const LineRec *lines, const uint32_t *sorted_beam, const uint32_t *tile_begin,
                             const uint32_t *tile_end, const double2 *factors, const int *reach, float *grid) {
  constexpr int kThreads = 32 * kWords;
  constexpr bool kHeavy = kWords > 2;
  static_assert(kWords == 2 || kWords == 8, "a light tile's 64 threads or a heavy tile's 256");
  const int tiles_y = (m.size_y + kTile - 1) / kTile;
  const int tx0 = m.x_begin + (static_cast<int>(tile) / tiles_y) * kTile;  // in the frame
  const int ty0 = (static_cast<int>(tile) % tiles_y) * kTile;
  const int cx = tx0 + t / kTile, cy = ty0 + t % kTile;
  const bool active = t < kTileThreads && inside(cx, cy, m);
  const size_t index = static_cast<size_t>(cx - m.x_begin) * m.size_y + cy;  // active cells only
  // The grid holds the result of earlier scans (all unknown for a fresh map):
  // this launch's updates come after theirs, as in the oracle's order.
  float cell = active ? grid[index] : egrid::kUnknown;
  unsigned count = 0;
  FixedPoints fixed;
  StartFactors known;
  const int w = t / 32;
  // 64-bit positions: a list can end near 2^32 (pairs are counted in 32 bits).
  const uint64_t begin = tile_begin[tile], end = tile_end[tile];
  // A heavy tile's thread fetches its beam of the next chunk, and the id of
  // its beam two chunks ahead: each load is issued a chunk before its value
  // is needed, so no round waits for the list's two dependent loads. (A
  // light tile has few rounds; the registers would cost it occupancy.)
  LineRec next;
  uint32_t ahead = 0;
  if (kHeavy) {
    if (begin + t < end) next = lines[sorted_beam[begin + t]];
    if (begin + kThreads + t < end) ahead = sorted_beam[begin + kThreads + t];
  }
  for (uint64_t base = begin; base < end; base += kThreads) {
    const int n = static_cast<int>(min(static_cast<uint64_t>(kThreads), end - base));
    for (int i = t; i < kTileThreads * kWords; i += kThreads) S.hit[i] = 0;
    if (t < n) S.beams[t] = kHeavy ? next : lines[sorted_beam[base + t]];
    __syncthreads();
    if (kHeavy) {
      if (base + kThreads + t < end) next = lines[ahead];
      if (base + 2 * kThreads + t < end) ahead = sorted_beam[base + 2 * kThreads + t];
    }
    if (32 * w < n)
      mark_word(S.beams + 32 * w, n - 32 * w, tx0, ty0, S.hit + w, kWords, kHeavy ? &S.words[w] : nullptr);
    __syncthreads();
    if (active && kHeavy) {
      for (int v = 0; v < kWords && 32 * v < n; ++v)
        count += drain_word(m, S.beams + 32 * v, S.hit[t * kWords + v], S.words[v], cx, cy, reach, factors, &fixed,
                            &known, &cell);
    } else if (active) {  // a light tile's two words as one mask of 64 beams
      const unsigned long long h = (static_cast<unsigned long long>(S.hit[2 * t + 1]) << 32) | S.hit[2 * t];
      count += drain_hits(m, S.beams, h, cx, cy, reach, factors, &fixed, &known, &cell);
    }
    __syncthreads();
  }
  if (active) grid[index] = cell;
  return count;
}

// Tiles whose lists are longer than this run as heavy tiles: a block of 256
// threads (chunks of 256 beams, 8 warps marking) each, in a launch of their
// own beside the light tiles' (a block of 64 threads each). A tile's list
// runs in order, so the longest lists (where the robot stood: fr079 has one
// of 25560 beams) bounded the kernel: a quarter of the rounds, marking and
// fetching spread over four times the warps, the next chunk fetched during
// this one, and words of beams with one start counted without walking once
// the cell settled take them out of the way. Measured on the H200 (fr079,
// vasco's defaults, tiles kernel): every tile 64 threads, one launch,
// 5.07 ms (the SMs busy 54 % of it); heavy tiles above 512 beams in the
// same launch (four light tiles a block) 3.92; apart on a second stream,
// above 4096 beams (at most 132) 3.89, above 2048 (at most 264) 3.81; with
// at most 4096 heavy tiles in one launch the map phase went 5.84 -> 7.28 ms.
// The heavy blocks run on a stream of the highest priority (TileStreams):
// without it the light launch took every multiprocessor first and the heavy
// tiles ran after it, alone (ncu on an H100: light 2.33 ms, heavy 1.28, the
// two together 3.62). session_bench on an H100 (two runs each, exact
// re-render, fr079 / fr101 ms): no priority 5.149 5.211 / 8.935 8.834; the
// heavy stream first, 264 heavy blocks 4.573 4.495 / 8.342 8.297; above
// 4096 beams 4.562 4.589 / 8.266 8.325; at most 132 heavy blocks (one an
// SM, the rest of its registers left to light tiles) 4.432 4.388 / 8.266
// 8.116.
constexpr uint32_t kHeavyList = 2048;
// At most this many tiles run heavy: the longest lists, a block each.
constexpr uint32_t kHeavyBlocks = 132;
constexpr int kLightWords = kTileThreads / 32, kHeavyWords = 8;
// The light blocks an SM must be able to hold at once (__launch_bounds__'s
// second argument): 16 leaves 64 registers a thread (a few spilled) where the
// compiler chose 80 (12 blocks an SM; 93 with the bound written as 1).
// session_bench on an H100, one run per bound (exact re-render, fr079 /
// fr101 ms): 12 blocks 5.549 / 9.418, 14: 5.437 / 9.135, 16: 5.420 / 9.055
// and 5.386 / 9.109 again, 18: 5.599 / 9.522, 20: 6.319 / 10.819 (the heavy
// blocks then at 110 registers). The heavy blocks' bound is 0, no minimum:
// the one-argument form's code, 100 registers (1 written out gives 110).
constexpr int kLightMinBlocks = 16;

// Block b runs tile order[b] when it is a heavy one (b < *heavy_count, for the
// heavy launch) or a light one (b >= *heavy_count, for the light launch). A
// tile no beam crosses keeps its cells as they are: its block returns before
// loading anything (most of a grid's tiles, all run last, each of which
// loaded the reach table, 8 KB at vasco's defaults: fr079 has 46,826 of its
// 59,488 tiles so, fr101 187,788 of 238,280; VASCO_CUDA_PROFILE counts them).
// The reach table is read from shared memory: reading it in place instead
// (a light block of a third the shared memory) made fr079's and fr101's
// exact re-renders 0.08 and 0.09 ms slower on the H100 (session_bench).
template <int kWords>
__global__ void __launch_bounds__(32 * kWords, kWords == kHeavyWords ? 0 : kLightMinBlocks)
    tiles_kernel(KernelModel<double> m, const LineRec *lines, const uint32_t *sorted_beam, const uint32_t *order,
                 const uint32_t *tile_begin, const uint32_t *tile_end, const uint32_t *heavy_count,
                 const double2 *factors, const int *reach_global, float *grid, unsigned long long *updates) {
  constexpr bool kHeavy = kWords == kHeavyWords;
  if ((blockIdx.x < *heavy_count) != kHeavy) return;  // the other launch's tile
  const uint32_t tile = order[blockIdx.x];
  if (tile_begin[tile] == tile_end[tile]) return;  // the same for the whole block
  __shared__ TileShared<kWords> S;
  extern __shared__ int reach_shared[];  // the reach table, when tables are used
  const int *reach = nullptr;
  if (reach_global) {
    for (int i = threadIdx.x; i < m.table_size; i += 32 * kWords) reach_shared[i] = reach_global[i];
    reach = reach_shared;
  }
  __syncthreads();
  const unsigned count = run_tile<kWords>(m, tile, threadIdx.x, S, lines, sorted_beam, tile_begin, tile_end,
                                          factors, reach, grid);
  const unsigned in_warp = warp_sum(count);
  if ((threadIdx.x & 31) == 0 && in_warp) atomicAdd(updates, static_cast<unsigned long long>(in_warp));
}

// *count = the number of leading entries of `lengths` (sorted, longest first)
// above kHeavyList, at most kHeavyBlocks.
__global__ void heavy_count_kernel(const uint32_t *lengths, size_t n, uint32_t *count) {
  size_t lo = 0, hi = n < kHeavyBlocks ? n : kHeavyBlocks;
  while (lo < hi) {
    const size_t mid = lo + (hi - lo) / 2;
    if (lengths[mid] > kHeavyList) lo = mid + 1;
    else hi = mid;
  }
  *count = static_cast<uint32_t>(lo);
}

__global__ void tile_keys_kernel(const uint32_t *begin, const uint32_t *end, size_t n,
                                 uint32_t *keys, uint32_t *ids) {
  const size_t t = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x;
  if (t >= n) return;
  keys[t] = end[t] - begin[t];
  ids[t] = static_cast<uint32_t>(t);
}

}  // namespace

size_t exact_order_temp_bytes(size_t num_tiles) {
  size_t bytes = 0;
  VG_CUDA_CHECK(cub::DeviceRadixSort::SortPairsDescending(
      nullptr, bytes, static_cast<const uint32_t *>(nullptr), static_cast<uint32_t *>(nullptr),
      static_cast<const uint32_t *>(nullptr), static_cast<uint32_t *>(nullptr),
      static_cast<int64_t>(num_tiles)));
  return bytes;
}

void exact_tile_order(const uint32_t *tile_begin, const uint32_t *tile_end, size_t num_tiles, size_t num_beams,
                      uint32_t *order, uint32_t *keys, uint32_t *keys_out, uint32_t *ids, uint32_t *heavy_count,
                      void *temp, size_t temp_bytes, cudaStream_t stream) {
  if (num_tiles == 0) return;
  tile_keys_kernel<<<blocks_for(num_tiles, 256), 256, 0, stream>>>(tile_begin, tile_end, num_tiles,
                                                                   keys, ids);
  VG_CUDA_CHECK_LAUNCH();
  VG_CUDA_CHECK(cub::DeviceRadixSort::SortPairsDescending(temp, temp_bytes, keys, keys_out, ids, order,
                                                          static_cast<int64_t>(num_tiles), 0, key_bits_above(num_beams),
                                                          stream));
  heavy_count_kernel<<<1, 1, 0, stream>>>(keys_out, num_tiles, heavy_count);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_exact_tiles(const KernelModel<double> &m, const LineRec *lines, const uint32_t *sorted_beam,
                        const uint32_t *order, const uint32_t *tile_begin, const uint32_t *tile_end,
                        const uint32_t *heavy_count, const double2 *factors, const int *reach, float *grid,
                        unsigned long long *updates, const TileStreams &streams) {
  const size_t tiles = static_cast<size_t>((m.size_x + kTile - 1) / kTile) *
                       ((m.size_y + kTile - 1) / kTile);
  if (tiles == 0) return;
  const size_t shared = reach ? static_cast<size_t>(m.table_size) * sizeof(int) : 0;
  // The heavy tiles on the side stream, beside the light ones: forked after
  // everything queued so far, joined before anything queued later.
  VG_CUDA_CHECK(cudaEventRecord(streams.fork, streams.main));
  VG_CUDA_CHECK(cudaStreamWaitEvent(streams.side, streams.fork, 0));
  const unsigned heavy_blocks = static_cast<unsigned>(tiles < kHeavyBlocks ? tiles : kHeavyBlocks);
  tiles_kernel<kHeavyWords><<<heavy_blocks, 32 * kHeavyWords, shared, streams.side>>>(
      m, lines, sorted_beam, order, tile_begin, tile_end, heavy_count, factors, reach, grid, updates);
  VG_CUDA_CHECK_LAUNCH();
  // kMaxExactTiles keeps this below 2^31 blocks.
  tiles_kernel<kLightWords><<<static_cast<unsigned>(tiles), 32 * kLightWords, shared, streams.main>>>(
      m, lines, sorted_beam, order, tile_begin, tile_end, heavy_count, factors, reach, grid, updates);
  VG_CUDA_CHECK_LAUNCH();
  VG_CUDA_CHECK(cudaEventRecord(streams.join, streams.side));
  VG_CUDA_CHECK(cudaStreamWaitEvent(streams.main, streams.join, 0));
}

}  // namespace cuda
}  // namespace vasco
