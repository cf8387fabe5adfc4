// Float mode of the CUDA backend: the paper's parallelization (a group of
// threads per beam, one thread per cell of the beam) done without lost
// updates, with every scan fused into one launch.
//
// Why fusing is allowed: the odds update multiplies the cell's odds by
// ((1-prior)/prior) * p/(1-p); in log-odds that is a sum,
//     L = logit(prior) + sum over updates of (logit(p) - logit(prior)),
// and a sum does not depend on the order of its terms. So all beams of all
// scans can be applied at once, with atomic adds (no update is lost). Only
// an exact sum is order-free: float atomics rounded after every add, so the
// order the adds happened to take showed in the map and no two runs agreed.
// The sums are therefore 64-bit fixed point added with integer atomics
// (egrid_kernels.h kFixedFracBits): the same bytes on every run.
//
// What this changes against the oracle: (1) single precision, increments
// rounded to 2^-24 log-odds, and a different association of the same
// product, so values differ in the last bits; (2) saturation — the oracle stores a float after every update, and
// once a cell rounds to exactly 1.0 (or 0.0) its odds are infinite (zero) and
// it stays there for good, while the log-odds sum keeps counting: a cell that
// the oracle pinned at 1.0 can come back below 1 here if enough free updates
// follow. Measured in the agreement tables (DESIGN §4).
#include <algorithm>

#include "cuda_check.h"
#include "egrid_kernels.h"
#include "warp_sum.cuh"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace cuda {
namespace {

constexpr int kWarpsPerBlock = 8;

// The cells within kNear - 1 steps of a scan's start cell are crossed by
// most of its beams (every beam updates the start cell itself), and their
// atomics contend in L2: they go to a block-private window in shared memory
// instead, and the window to the sums once per scan. Integer sums: the same
// bytes as adding each to the sums. Measured on the H200 (map phase, fr079 /
// fr101): no window 1.93 / 3.35 ms, kNear 8 1.81 / 3.23, kNear 16 1.66 / 3.24.
constexpr int kNear = 16;
constexpr int kWindow = 2 * kNear - 1;  // cells per side, centred on the start cell

struct NearWindow {
  unsigned long long *cells;  // kWindow * kWindow shared sums
  int x1, y1;                 // the scan's start cell
};

// The sums are fixed point (egrid_kernels.h kFixedCountBits): 0 means
// "never updated", and every update adds its count bit, so no separate
// touched array and none of its stores.

// The fixed-point increment of an update at distance d by a beam of range r
// (egrid_kernels.h kFixedFracBits); false where the beam stops (d >= max).
// The one expression of float mode's evidence: the tables hold its values.
__device__ __forceinline__ bool fixed_increment(const KernelModel<float> &m, float d, float r, long long *q) {
  float p;
  if (!egrid::sensor_model(m.sensor, d, r, &p)) return false;
  // |x| > 64 saturates a float probability anyway; the clamp keeps a p that
  // rounds to 1.0f in float (a prior of 1 - 1e-9, say) a finite increment.
  const float x = fminf(fmaxf(__logf(p / (1.0f - p)) - m.logodds_prior, -64.0f), 64.0f);
  *q = __float2ll_rn(x * static_cast<float>(1 << kFixedFracBits));
  return true;
}

__device__ __forceinline__ unsigned long long fixed_term(long long q) {
  return (static_cast<unsigned long long>(q) << kFixedCountBits) + 1ull;
}

__device__ __forceinline__ void add_fixed(unsigned long long *sums, size_t c, long long q) {
  atomicAdd(sums + c, fixed_term(q));
}

// The distance of a cell i, j cells from the start, as the oracle's float
// port has it (1e6 past the table: never updated).
__device__ __forceinline__ float float_distance(const KernelModel<float> &m, int i, int j) {
  return (i >= m.table_size || j >= m.table_size) ? 1e6f
                                                  : sqrtf(static_cast<float>(i * i + j * j)) * m.resolution;
}

// One update of (cx, cy), computed in full (degenerate lines); sets *stop
// where the beam stops.
__device__ __forceinline__ void add_evidence(const KernelModel<float> &m, int cx, int cy, int x1, int y1,
                                             float r, unsigned long long *sums, unsigned *count, bool *stop) {
  const int64_t bx = static_cast<int64_t>(cx) - m.x_begin;  // cx: anywhere an int reaches
  if (bx < 0 || bx >= m.size_x || cy < 0 || cy >= m.size_y) return;
  long long q;
  if (!fixed_increment(m, float_distance(m, abs(cx - x1), abs(cy - y1)), r, &q)) {
    *stop = true;
    return;
  }
  add_fixed(sums, static_cast<size_t>(bx) * m.size_y + cy, q);
  ++*count;
}

// increments[i * T + j] = {free, occupied} fixed-point increments at offset
// (i, j), or kFloatStops where the beam stops.
__global__ void float_tables_kernel(KernelModel<float> m, int2 *increments) {
  const int T = m.table_size;
  for (int idx = blockIdx.x * blockDim.x + threadIdx.x; idx < T * T; idx += gridDim.x * blockDim.x) {
    const float d = float_distance(m, idx / T, idx % T);
    long long f, o;
    if (!fixed_increment(m, d, HUGE_VALF, &f) || !fixed_increment(m, d, -HUGE_VALF, &o)) {
      increments[idx] = make_int2(kFloatStops, kFloatStops);
    } else {
      increments[idx] = make_int2(static_cast<int>(f), static_cast<int>(o));
    }
  }
}

// The closed-form walk of one beam, lane by lane: lane l takes steps l, l+32,
// ... The minor offset (2b·k + bias) / 2a advances by a constant quotient and
// remainder per 32 steps, so each lane divides once. With tables, an update
// is a lookup and a comparison (d < r, the sensor model's free test, with the
// same float distance); without, fixed_increment in full.
//
// A beam whose major axis is x (not steep) steps along x from lane to lane:
// in the x-major sums its 32 lanes' adds are a column apart each, 32 L2
// sectors per warp. With `across` (a y-major accumulator of the same cells)
// they go there instead, to consecutive addresses; launch_float_map adds it
// to the sums afterwards. Integer sums: the same bytes either way.
template <bool kBanded>
__device__ __forceinline__ void walk_closed_form(const KernelModel<float> &m, const int2 *increments,
                                                 const egrid::LineParams &p, int x1, int y1, float r, int lane,
                                                 unsigned long long *sums, unsigned long long *across,
                                                 const NearWindow &near, unsigned *updates) {
  unsigned long long *const target = !p.steep && across != nullptr ? across : sums;
  // Cells beyond table_size steps are never updated (see oracle.h); cells
  // with d >= max are skipped, which equals the oracle's stop because d
  // never decreases along the walk.
  const int k_end = min(p.major_len, m.table_size - 1);
  if (lane > k_end) return;
  const int64_t two_a = p.a ? 2 * static_cast<int64_t>(p.a) : 1, two_b = p.a ? 2 * static_cast<int64_t>(p.b) : 0;
  const int64_t num = two_b * lane + (p.a ? p.a - (p.inc < 0 ? 1 : 0) : 0), stride = two_b * 32;
  int mm = static_cast<int>(num / two_a);
  int64_t rem = num % two_a;
  const int dq = static_cast<int>(stride / two_a);
  const int64_t dr = stride % two_a;
  const int sx1 = p.steep ? p.y1 : p.x1, sy1 = p.flipped ? -(p.steep ? p.x1 : p.y1) : (p.steep ? p.x1 : p.y1);
  for (int k = lane; k <= k_end; k += 32) {
    const int maj = sx1 + p.inc * k;
    const int mn = p.flipped ? -(sy1 + p.inc * mm) : sy1 + p.inc * mm;
    const int cx = p.steep ? mn : maj, cy = p.steep ? maj : mn;
    // The column in the grid (x_begin: a band's first; a session's start
    // cells lie in its frame, so this stays well inside an int). A whole
    // grid's kernel goes without the subtraction (measured: 2 % of its time).
    const int bx = kBanded ? cx - m.x_begin : cx;
    if (bx >= 0 && bx < m.size_x && cy >= 0 && cy < m.size_y) {
      const int i = p.steep ? mm : k, j = p.steep ? k : mm;  // |cx - x1|, |cy - y1|
      long long q;
      bool update;
      if (increments) {
        const int2 e = increments[i * m.table_size + j];
        update = e.x != kFloatStops;
        q = float_distance(m, i, j) < r ? e.x : e.y;
      } else {
        update = fixed_increment(m, float_distance(m, abs(cx - x1), abs(cy - y1)), r, &q);
      }
      if (update) {
        if (i < kNear && j < kNear) {
          atomicAdd(near.cells + (cx - near.x1 + kNear - 1) * kWindow + (cy - near.y1 + kNear - 1), fixed_term(q));
        } else if (target == across) {
          add_fixed(across, static_cast<size_t>(cy) * m.size_x + bx, q);
        } else {
          add_fixed(sums, static_cast<size_t>(bx) * m.size_y + cy, q);
        }
        ++*updates;
      }
    }
    mm += dq;
    rem += dr;
    if (rem >= two_a) {
      rem -= two_a;
      ++mm;
    }
  }
}

template <bool kBanded>
__global__ void __launch_bounds__(kWarpsPerBlock * 32)
    float_map_kernel(KernelModel<float> m, const int2 *increments, const FloatScan *scans, int num_scans, int parts,
                     const float *ranges, unsigned long long *sums, unsigned long long *across,
                     unsigned long long *counters) {
  const int lane = threadIdx.x & 31, warp = threadIdx.x >> 5;
  unsigned used = 0, skipped = 0, updates = 0;
  __shared__ unsigned long long window[kWindow * kWindow];
  // `parts` blocks share a scan (several when a few scans are inserted, so
  // that one scan still fills the GPU), each taking every parts-th warp's beams.
  for (int sp = blockIdx.x; sp < num_scans * parts; sp += gridDim.x) {
    const FloatScan sc = scans[sp / parts];
    const int part = sp % parts;
    const NearWindow near{window, sc.x1, sc.y1};
    for (int c = threadIdx.x; c < kWindow * kWindow; c += blockDim.x) window[c] = 0;
    __syncthreads();
    for (int b = part * kWarpsPerBlock + warp; b < sc.beam_count; b += kWarpsPerBlock * parts) {
      const float r = ranges[sc.beam_begin + b];
      if (!(r < 50.0f)) {
        skipped += lane == 0;
        continue;
      }
      used += lane == 0;
      float sn, cs;
      sincosf(sc.theta + sc.first + static_cast<float>(b) * sc.step, &sn, &cs);
      const int x2 = egrid::trunc_to_int(sc.lx + (r + m.wall) * cs / m.resolution);
      const int y2 = egrid::trunc_to_int(sc.ly + (r + m.wall) * sn / m.resolution);
      if (!egrid::is_closed_form_line(sc.x1, sc.y1, x2, y2)) {
        // Degenerate line (a range of -inf): one lane walks it sequentially.
        if (lane == 0) {
          bool stop = false;
          egrid::walk_line(sc.x1, sc.y1, x2, y2, m.table_size, [&](int cx, int cy, int) {
            add_evidence(m, cx, cy, sc.x1, sc.y1, r, sums, &updates, &stop);
            return !stop;
          });
        }
        continue;
      }
      const egrid::LineParams p = egrid::line_params(sc.x1, sc.y1, x2, y2);
      walk_closed_form<kBanded>(m, increments, p, sc.x1, sc.y1, r, lane, sums, across, near, &updates);
    }
    __syncthreads();
    // The window to the sums: only cells of the grid were added to it.
    for (int c = threadIdx.x; c < kWindow * kWindow; c += blockDim.x) {
      if (window[c] == 0) continue;
      const int bx = sc.x1 + c / kWindow - (kNear - 1) - m.x_begin, cy = sc.y1 + c % kWindow - (kNear - 1);
      atomicAdd(sums + static_cast<size_t>(bx) * m.size_y + cy, window[c]);
    }
    __syncthreads();
  }
  // counters: beams used, beams skipped, cell updates
  used = warp_sum(used);
  skipped = warp_sum(skipped);
  updates = warp_sum(updates);
  if (lane == 0) {
    if (used) atomicAdd(counters + 0, static_cast<unsigned long long>(used));
    if (skipped) atomicAdd(counters + 1, static_cast<unsigned long long>(skipped));
    if (updates) atomicAdd(counters + 2, static_cast<unsigned long long>(updates));
  }
}

// sums[x * size_y + y] += across[y * size_x + x]: a 32 x 32 tile through
// shared memory, so that both the read and the write are coalesced.
constexpr int kAcrossTile = 32, kAcrossRows = 8;

__global__ void add_across_kernel(int size_x, int size_y, const unsigned long long *across, unsigned long long *sums) {
  __shared__ unsigned long long tile[kAcrossTile][kAcrossTile + 1];  // +1: no bank conflicts on the transposed read
  const int x0 = blockIdx.x * kAcrossTile, y0 = blockIdx.y * kAcrossTile;
  for (int r = threadIdx.y; r < kAcrossTile; r += kAcrossRows) {
    const int x = x0 + threadIdx.x, y = y0 + r;
    tile[r][threadIdx.x] = x < size_x && y < size_y ? across[static_cast<size_t>(y) * size_x + x] : 0ull;
  }
  __syncthreads();
  for (int r = threadIdx.y; r < kAcrossTile; r += kAcrossRows) {
    const int x = x0 + r, y = y0 + threadIdx.x;
    const unsigned long long v = tile[threadIdx.x][r];
    if (x < size_x && y < size_y && v != 0) sums[static_cast<size_t>(x) * size_y + y] += v;
  }
}

__global__ void fill_kernel(float *grid, size_t n, float value) {
  for (size_t c = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x; c < n;
       c += static_cast<size_t>(gridDim.x) * blockDim.x)
    grid[c] = value;
}

__global__ void finalize_kernel(KernelModel<float> m, float *grid, const uint8_t *touched, size_t n) {
  for (size_t c = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x; c < n;
       c += static_cast<size_t>(gridDim.x) * blockDim.x) {
    if (touched && !touched[c])
      grid[c] = egrid::kUnknown;
    else
      grid[c] = prob_of_logodds(m.logodds_prior, grid[c]);
  }
}

__global__ void from_prob_kernel(KernelModel<float> m, const float *probs, unsigned long long *sums, size_t n) {
  // 0 and 1 (log-odds -inf and +inf) saturate at +-2^20 log-odds, which no
  // later update can bring back (the host's kFixedLimit check).
  const float kSaturated = 1048576.0f;
  for (size_t c = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x; c < n;
       c += static_cast<size_t>(gridDim.x) * blockDim.x) {
    const float p = probs[c];
    if (p == egrid::kUnknown) {
      sums[c] = 0;
      continue;
    }
    const float x = fminf(fmaxf(logf(p / (1.0f - p)) - m.logodds_prior, -kSaturated), kSaturated);
    const long long q = __float2ll_rn(x * static_cast<float>(1 << kFixedFracBits));
    sums[c] = (static_cast<unsigned long long>(q) << kFixedCountBits) + 1ull;
  }
}

unsigned fill_blocks(size_t n) { return static_cast<unsigned>(std::min<size_t>((n + 255) / 256, 65536)); }

}  // namespace

bool kernels_runnable_on_current_device(std::string *why) {
  cudaFuncAttributes attr;
  const cudaError_t err = cudaFuncGetAttributes(&attr, fill_kernel);
  if (err == cudaSuccess) return true;
  (void)cudaGetLastError();  // clear it: the caller falls back to the CPU
  if (why != nullptr) *why = cudaGetErrorString(err);
  return false;
}

void launch_fill(float *cells, size_t num_cells, float value, cudaStream_t stream) {
  if (num_cells == 0) return;
  fill_kernel<<<fill_blocks(num_cells), 256, 0, stream>>>(cells, num_cells, value);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_float_from_prob(const KernelModel<float> &m, const float *probs, unsigned long long *sums,
                            size_t num_cells, cudaStream_t stream) {
  if (num_cells == 0) return;
  from_prob_kernel<<<fill_blocks(num_cells), 256, 0, stream>>>(m, probs, sums, num_cells);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_float_clear(unsigned long long *sums, size_t num_cells, cudaStream_t stream) {
  if (num_cells == 0) return;
  VG_CUDA_CHECK(cudaMemsetAsync(sums, 0, num_cells * sizeof(unsigned long long), stream));
}

void launch_float_tables(const KernelModel<float> &m, int2 *increments, cudaStream_t stream) {
  const size_t n = static_cast<size_t>(m.table_size) * m.table_size;
  if (n == 0) return;
  float_tables_kernel<<<fill_blocks(n), 256, 0, stream>>>(m, increments);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_float_map(const KernelModel<float> &m, const int2 *increments, const FloatScan *scans, int num_scans,
                      const float *ranges, unsigned long long *sums, unsigned long long *across,
                      unsigned long long *counters, cudaStream_t stream) {
  if (num_scans <= 0) return;
  const size_t cells = static_cast<size_t>(m.size_x) * static_cast<size_t>(m.size_y);
  if (across != nullptr) VG_CUDA_CHECK(cudaMemsetAsync(across, 0, cells * sizeof(unsigned long long), stream));
  // A full render has thousands of scans: a block each. An insert of a few
  // scans splits each over up to 48 blocks (a warp per beam either way).
  const int parts = num_scans >= 1024 ? 1 : std::min(48, (1024 + num_scans - 1) / num_scans);
  // A band of a split render (x_begin > 0) offsets its columns; a whole grid, or the first band, needs not.
  auto *kernel = m.x_begin != 0 ? float_map_kernel<true> : float_map_kernel<false>;
  kernel<<<num_scans * parts, kWarpsPerBlock * 32, 0, stream>>>(m, increments, scans, num_scans, parts, ranges, sums,
                                                                 across, counters);
  VG_CUDA_CHECK_LAUNCH();
  if (across == nullptr) return;
  const dim3 tiles((m.size_x + kAcrossTile - 1) / kAcrossTile, (m.size_y + kAcrossTile - 1) / kAcrossTile), threads(kAcrossTile, kAcrossRows);
  add_across_kernel<<<tiles, threads, 0, stream>>>(m.size_x, m.size_y, across, sums);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_float_finalize(const KernelModel<float> &m, float *grid, const uint8_t *touched,
                           size_t num_cells, cudaStream_t stream) {
  if (num_cells == 0) return;
  const unsigned blocks = static_cast<unsigned>(std::min<size_t>((num_cells + 255) / 256, 65536));
  finalize_kernel<<<blocks, 256, 0, stream>>>(m, grid, touched, num_cells);
  VG_CUDA_CHECK_LAUNCH();
}

}  // namespace cuda
}  // namespace vasco
