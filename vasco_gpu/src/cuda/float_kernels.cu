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
// fr101): no window 1.93 / 3.35 ms, kNear 8 1.81 / 3.23, kNear 16 1.66 / 3.24;
// with the beams planned a lane each (fr079 paper / defaults): kNear 16
// 1.14 / 1.19 ms, 24 1.05 / 1.11, 32 0.95 / 1.01 (a warp's first 32 steps
// all in shared memory), 39 1.09 / 1.15 (the window's 47 KB cost blocks).
constexpr int kNear = 32;
constexpr int kWindow = 2 * kNear - 1;  // cells per side, centred on the start cell

struct NearWindow {
  unsigned long long *cells;  // kWindow * kWindow shared sums
  int x1, y1;                 // the scan's start cell
};

// Where the map kernel adds an update: the map's sums (every launch but
// mapping_bench's floors), or a floor's register or shared tile (egrid_kernels.h FloatFloor).
enum class Accumulate { Sums, Registers, SharedTile };
constexpr int kFloorTile = 64;
template <Accumulate kAcc>
constexpr int kWindowCells = kAcc == Accumulate::SharedTile ? kFloorTile * kFloorTile : kWindow * kWindow;

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

// A beam's closed-form walk, as every lane of the warp that walks it needs
// it. One lane plans each beam (plan_beam) and the warp shares the plans
// (share_plan): the set-up — the angle's sine and cosine, the end cell, the
// line's parameters, three divisions and a search — then costs a lane's work
// instead of a warp's, where an average fr079 beam gives each lane only 3 or
// 4 cells to update. Measured on the H200 (fr079, vasco's defaults, map
// phase): 1.38 -> 1.19 ms, 1.11 G -> 0.68 G instructions.
struct BeamPlan {
  int kind;        // kSkipBeam, kDegenerateBeam or kClosedBeam
  int flags;       // kPlanSteep | kPlanFlipped | kPlanBackward (closed only)
  int sx1, sy1;    // the start in the swapped/flipped frame (major, minor)
  int k_end;       // last step that can update a cell
  int two_a, bias; // minor offset m(k) = (two_b * k + bias) / two_a
  int two_b;
  int dq, dr;      // m(k + 32) = m(k) + dq, or + dq + 1 when the remainder passes two_a (dr < two_a)
  int n_free;      // i*i + j*j < n_free exactly where the beam's float distance is below its range
  int x2, y2;      // the end cell (degenerate lines)
  float r;
};
constexpr int kSkipBeam = 0, kDegenerateBeam = 1, kClosedBeam = 2;
constexpr int kPlanSteep = 1, kPlanFlipped = 2, kPlanBackward = 4;

// The first n in [0, n_max] with !(float distance of n < r), n_max + 1 if
// none: the free test of every update in one comparison of integers. The
// float distance sqrtf((float)n) * resolution never decreases as n grows
// (each operation is correctly rounded, so monotone), so walking from any
// guess to where the test turns gives it exactly; (r / resolution)^2 is
// within a few units of it. Tables only: n = i*i + j*j < 2 * 2048^2 is exact
// in a float.
__device__ __forceinline__ int first_not_free(const KernelModel<float> &m, float r) {
  const int n_max = 2 * (m.table_size - 1) * (m.table_size - 1);
  auto is_free = [&](int n) { return sqrtf(static_cast<float>(n)) * m.resolution < r; };
  const float x = r / m.resolution, guess = x * x;
  int n = !(r > 0.0f) ? 0 : guess >= static_cast<float>(n_max) ? n_max + 1 : static_cast<int>(guess);
  while (n > 0 && !is_free(n - 1)) --n;
  while (n <= n_max && is_free(n)) ++n;
  return n;
}

__device__ BeamPlan plan_beam(const KernelModel<float> &m, const FloatScan &sc, const float *ranges, int b,
                              bool tables) {
  BeamPlan w{};
  w.kind = kSkipBeam;
  if (b >= sc.beam_count) return w;
  w.r = ranges[sc.beam_begin + b];
  if (!(w.r < 50.0f)) return w;
  float sn, cs;
  sincosf(sc.theta + sc.first + static_cast<float>(b) * sc.step, &sn, &cs);
  w.x2 = egrid::trunc_to_int(sc.lx + (w.r + m.wall) * cs / m.resolution);
  w.y2 = egrid::trunc_to_int(sc.ly + (w.r + m.wall) * sn / m.resolution);
  if (!egrid::is_closed_form_line(sc.x1, sc.y1, w.x2, w.y2)) {
    w.kind = kDegenerateBeam;  // a range of -inf: walked sequentially
    return w;
  }
  w.kind = kClosedBeam;
  const egrid::LineParams p = egrid::line_params(sc.x1, sc.y1, w.x2, w.y2);
  w.flags = (p.steep ? kPlanSteep : 0) | (p.flipped ? kPlanFlipped : 0) | (p.inc < 0 ? kPlanBackward : 0);
  w.sx1 = p.steep ? p.y1 : p.x1;
  w.sy1 = p.flipped ? -(p.steep ? p.x1 : p.y1) : (p.steep ? p.x1 : p.y1);
  // Cells beyond table_size steps are never updated (see oracle.h); cells
  // with d >= max are skipped, which equals the oracle's stop because d
  // never decreases along the walk.
  w.k_end = min(p.major_len, m.table_size - 1);
  // a, b < 2^29 (is_closed_form_line): 2a and 2b fit an int; 32 steps of 2b may not.
  w.two_a = p.a ? 2 * p.a : 1;
  w.two_b = p.a ? 2 * p.b : 0;
  w.bias = p.a ? p.a - (p.inc < 0 ? 1 : 0) : 0;
  const int64_t stride = 32 * static_cast<int64_t>(w.two_b);
  w.dq = static_cast<int>(stride / w.two_a);
  w.dr = static_cast<int>(stride % w.two_a);
  w.n_free = tables ? first_not_free(m, w.r) : 0;
  return w;
}

__device__ __forceinline__ BeamPlan share_plan(const BeamPlan &w, int src) {
  constexpr unsigned kAll = 0xffffffffu;
  BeamPlan s;
  s.kind = __shfl_sync(kAll, w.kind, src);
  s.flags = __shfl_sync(kAll, w.flags, src);
  s.sx1 = __shfl_sync(kAll, w.sx1, src);
  s.sy1 = __shfl_sync(kAll, w.sy1, src);
  s.k_end = __shfl_sync(kAll, w.k_end, src);
  s.two_a = __shfl_sync(kAll, w.two_a, src);
  s.bias = __shfl_sync(kAll, w.bias, src);
  s.two_b = __shfl_sync(kAll, w.two_b, src);
  s.dq = __shfl_sync(kAll, w.dq, src);
  s.dr = __shfl_sync(kAll, w.dr, src);
  s.n_free = __shfl_sync(kAll, w.n_free, src);
  s.x2 = __shfl_sync(kAll, w.x2, src);
  s.y2 = __shfl_sync(kAll, w.y2, src);
  s.r = __shfl_sync(kAll, w.r, src);
  return s;
}

// The minor offset at step k <= k_end: (two_b * k + bias) / two_a, and its
// remainder, in 32 bits when they fit (every beam of a table-sized walk at
// ordinary resolutions), else in 64.
__device__ __forceinline__ void minor_offset(const BeamPlan &w, int k, int *mm, int *rem) {
  const int64_t num = static_cast<int64_t>(w.two_b) * k + w.bias;
  if (num <= INT32_MAX) {
    const unsigned n32 = static_cast<unsigned>(num), q = n32 / static_cast<unsigned>(w.two_a);
    *mm = static_cast<int>(q);
    *rem = static_cast<int>(n32 - q * static_cast<unsigned>(w.two_a));
  } else {
    *mm = static_cast<int>(num / w.two_a);
    *rem = static_cast<int>(num % w.two_a);
  }
}

// The closed-form walk of one beam, lane by lane: lane l takes steps l, l+32,
// ... The minor offset advances by a constant quotient and remainder per 32
// steps, so each lane divides once. With tables, an update is a lookup and a
// comparison of integers (n < n_free: the free test d < r, see
// first_not_free); without, fixed_increment in full. The tables depend on
// i*i + j*j only, so they are symmetric: looking up (minor offset, step)
// makes the lanes' loads consecutive whatever the beam's direction.
//
// A beam whose major axis is x (not steep) steps along x from lane to lane:
// in the x-major sums its 32 lanes' adds are a column apart each, 32 L2
// sectors per warp. With `across` (a y-major accumulator of the same cells)
// they go there instead, to consecutive addresses; launch_float_map adds it
// to the sums afterwards. Integer sums: the same bytes either way.
template <bool kBanded, Accumulate kAcc>
__device__ __forceinline__ void walk_closed_form(const KernelModel<float> &m, const int2 *increments,
                                                 const BeamPlan &w, int x1, int y1, int lane,
                                                 unsigned long long *sums, unsigned long long *across,
                                                 const NearWindow &near, unsigned *updates,
                                                 unsigned long long *sink) {
  if (lane > w.k_end) return;
  const bool steep = w.flags & kPlanSteep, flipped = w.flags & kPlanFlipped;
  const int inc = w.flags & kPlanBackward ? -1 : 1;
  unsigned long long *const target = !steep && across != nullptr ? across : sums;
  int mm, rem;
  minor_offset(w, lane, &mm, &rem);
  for (int k = lane; k <= w.k_end; k += 32) {
    const int maj = w.sx1 + inc * k;
    const int mn = flipped ? -(w.sy1 + inc * mm) : w.sy1 + inc * mm;
    const int cx = steep ? mn : maj, cy = steep ? maj : mn;
    // The column in the grid (x_begin: a band's first; a session's start
    // cells lie in its frame, so this stays well inside an int). A whole
    // grid's kernel goes without the subtraction (measured: 2 % of its time).
    const int bx = kBanded ? cx - m.x_begin : cx;
    if (bx >= 0 && bx < m.size_x && cy >= 0 && cy < m.size_y) {
      long long q;
      bool update;
      if (increments) {
        // mm <= k < table_size (the minor offset never outruns the step).
        const int2 e = increments[mm * m.table_size + k];
        update = e.x != kFloatStops;
        q = mm * mm + k * k < w.n_free ? e.x : e.y;
      } else {
        update = fixed_increment(m, float_distance(m, abs(cx - x1), abs(cy - y1)), w.r, &q);
      }
      if (update && kAcc == Accumulate::Registers) {
        *sink += fixed_term(q);
        ++*updates;
      } else if (update && kAcc == Accumulate::SharedTile) {
        atomicAdd(near.cells + (cx & (kFloorTile - 1)) * kFloorTile + (cy & (kFloorTile - 1)), fixed_term(q));
        ++*updates;
      } else if (update) {
        if (k < kNear) {  // then mm < kNear too: inside the window
          atomicAdd(near.cells + (cx - near.x1 + kNear - 1) * kWindow + (cy - near.y1 + kNear - 1), fixed_term(q));
        } else if (target == across) {
          add_fixed(across, static_cast<size_t>(cy) * m.size_x + bx, q);
        } else {
          add_fixed(sums, static_cast<size_t>(bx) * m.size_y + cy, q);
        }
        ++*updates;
      }
    }
    mm += w.dq;
    rem += w.dr;
    if (rem >= w.two_a) {
      rem -= w.two_a;
      ++mm;
    }
  }
}

template <bool kBanded, Accumulate kAcc = Accumulate::Sums>
__global__ void __launch_bounds__(kWarpsPerBlock * 32, 5)
    float_map_kernel(KernelModel<float> m, const int2 *increments, const FloatScan *scans, int num_scans, int parts,
                     const float *ranges, unsigned long long *sums, unsigned long long *across,
                     unsigned long long *counters) {
  const int lane = threadIdx.x & 31, warp = threadIdx.x >> 5;
  unsigned used = 0, skipped = 0, updates = 0;
  unsigned long long sink = 0;  // the Registers floor's
  __shared__ unsigned long long window[kWindowCells<kAcc>];
  // `parts` blocks share a scan (several when a few scans are inserted, so
  // that one scan still fills the GPU), each taking every parts-th warp's beams.
  for (int sp = blockIdx.x; sp < num_scans * parts; sp += gridDim.x) {
    const FloatScan sc = scans[sp / parts];
    const int part = sp % parts;
    const NearWindow near{window, sc.x1, sc.y1};
    for (int c = threadIdx.x; c < kWindowCells<kAcc>; c += blockDim.x) window[c] = 0;
    __syncthreads();
    // The warp's beams are first + l * stride; a round plans 32 of them, a
    // lane each, and walks them one after the other.
    const int first = part * kWarpsPerBlock + warp, stride = kWarpsPerBlock * parts;
    for (int round = first; round < sc.beam_count; round += 32 * stride) {
      const int b = round + lane * stride;
      const BeamPlan mine = plan_beam(m, sc, ranges, b, increments != nullptr);
      used += mine.kind != kSkipBeam;
      skipped += mine.kind == kSkipBeam && b < sc.beam_count;
      for (unsigned todo = __ballot_sync(0xffffffffu, mine.kind != kSkipBeam); todo != 0; todo &= todo - 1) {
        const BeamPlan w = share_plan(mine, __ffs(todo) - 1);
        if (w.kind == kClosedBeam) {
          walk_closed_form<kBanded, kAcc>(m, increments, w, sc.x1, sc.y1, lane, sums, across, near, &updates, &sink);
        } else if (lane == 0) {  // degenerate line (a range of -inf): one lane walks it sequentially
          bool stop = false;
          egrid::walk_line(sc.x1, sc.y1, w.x2, w.y2, m.table_size, [&](int cx, int cy, int) {
            add_evidence(m, cx, cy, sc.x1, sc.y1, w.r, sums, &updates, &stop);
            return !stop;
          });
        }
      }
    }
    __syncthreads();
    // The window to the sums: only cells of the grid were added to it.
    for (int c = threadIdx.x; kAcc == Accumulate::Sums && c < kWindow * kWindow; c += blockDim.x) {
      if (window[c] == 0) continue;
      const int bx = sc.x1 + c / kWindow - (kNear - 1) - m.x_begin, cy = sc.y1 + c % kWindow - (kNear - 1);
      atomicAdd(sums + static_cast<size_t>(bx) * m.size_y + cy, window[c]);
    }
    __syncthreads();
  }
  if (kAcc == Accumulate::Registers) {  // kept, so the floor's walk is not dead code: one add a warp
    for (int offset = 16; offset > 0; offset >>= 1) sink += __shfl_xor_sync(0xffffffffu, sink, offset);
    if (lane == 0 && sink != 0) atomicAdd(sums, sink);
  }
  if (kAcc == Accumulate::SharedTile && threadIdx.x == 0) atomicAdd(sums, window[0]);
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

// Blocks per scan of the map kernel: a full render has thousands of scans, a
// block each; an insert of a few scans splits each over up to 48 blocks (a
// warp per beam either way), so that one scan still fills the GPU.
int scan_parts(int num_scans) { return num_scans >= 1024 ? 1 : std::min(48, (1024 + num_scans - 1) / num_scans); }

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
  const int parts = scan_parts(num_scans);
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

void launch_float_map_floor(FloatFloor floor, const KernelModel<float> &m, const int2 *increments,
                            const FloatScan *scans, int num_scans, const float *ranges, unsigned long long *sums,
                            unsigned long long *counters, cudaStream_t stream) {
  if (num_scans <= 0) return;
  const int parts = scan_parts(num_scans);
  auto *kernel = floor == FloatFloor::Registers ? float_map_kernel<false, Accumulate::Registers>
                                                : float_map_kernel<false, Accumulate::SharedTile>;
  kernel<<<num_scans * parts, kWarpsPerBlock * 32, 0, stream>>>(m, increments, scans, num_scans, parts, ranges, sums,
                                                                 nullptr, counters);
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
