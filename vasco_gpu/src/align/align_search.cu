// align_search.cu — the device side of the GPU global search (align_gpu.h):
// every leaf of the coarse search space scored, a block per tile of
// translations of one rotation, the local maxima listed.
//
// A block scores an 18 x 32 tile of translations (a 16 x 30 interior and a
// one-cell halo, so that each interior leaf sees its eight neighbours), three
// leaves a thread; the rotation's point cells, rotated by the block into
// shared memory a chunk at a time, are read by every thread at once (a
// broadcast), and the field, x-major, is read at consecutive y by a warp's
// consecutive threads. The field of a coarse search is small (tens of KiB
// for a building), so its reads stay in L1.
#include <cuda_runtime.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "align_gpu.h"
#include "cuda_check.h"
#include "vasco_gpu/error.h"

namespace vasco {
namespace align_detail {
namespace {

constexpr int kTileX = 16, kTileY = 30;                 // interior leaves
constexpr int kHaloX = kTileX + 2, kHaloY = kTileY + 2;  // scored leaves
constexpr int kThreads = 192;
constexpr int kPerThread = kHaloX * kHaloY / kThreads;  // 3
static_assert(kPerThread * kThreads == kHaloX * kHaloY, "a tile's leaves split evenly over the threads");
constexpr int kChunk = 2048;  // points rotated into shared memory at a time

struct RawLeaf {
  int rotation, tx, ty;
  float sum;
};

// A float as an int that orders as the float does (for atomicMax).
__device__ inline int ordered(float v) {
  const int i = __float_as_int(v);
  return i >= 0 ? i : i ^ 0x7fffffff;
}
// The float of ordered(); INT_MIN (below every float's) is -inf.
inline float from_ordered(int i) {
  if (i == INT_MIN) return -INFINITY;
  const int bits = i >= 0 ? i : i ^ 0x7fffffff;
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

struct Launch {
  const double *px, *py;
  int n;
  double c_x, c_y, h;
  const double *cos_k, *sin_k;
  const TranslationBox *box;
  int tiles_y, tiles;  // tiles per rotation: tiles_x * tiles_y
  const float *field;
  int size_x, size_y;
  float floor;
  RawLeaf *out;
  unsigned int *count;
  int capacity;
  int *best;
};

// rotated_cells (align_score.h) for points [start, start + m): each
// operation rounded on its own, as the host (built without contraction)
// rounds it, so that the cells are the CPU's.
__device__ void rotate_chunk(const Launch &a, double c, double s, int start, int m, int32_t *cx, int32_t *cy) {
  for (int i = threadIdx.x; i < m; i += kThreads) {
    const double dx = __dsub_rn(a.px[start + i], a.c_x), dy = __dsub_rn(a.py[start + i], a.c_y);
    cx[i] = static_cast<int32_t>(floor(__ddiv_rn(__dsub_rn(__dmul_rn(c, dx), __dmul_rn(s, dy)), a.h)));
    cy[i] = static_cast<int32_t>(floor(__ddiv_rn(__dadd_rn(__dmul_rn(s, dx), __dmul_rn(c, dy)), a.h)));
  }
}

// The block's largest sum into *best: the threads' values reduced in
// shared memory (once a block: nothing to gain from shuffles), one atomic.
__device__ void report_best(float v, float *scratch, int *best) {
  scratch[threadIdx.x] = v;
  __syncthreads();
  if (threadIdx.x != 0) return;
  for (int i = 1; i < kThreads; ++i) v = fmaxf(v, scratch[i]);
  if (v > -INFINITY) atomicMax(best, ordered(v));
}

__global__ void __launch_bounds__(kThreads) score_leaves(Launch a) {
  const int k = static_cast<int>(blockIdx.x / a.tiles), tile = static_cast<int>(blockIdx.x % a.tiles);
  const TranslationBox b = a.box[k];
  const int x0 = b.x0 + (tile / a.tiles_y) * kTileX, y0 = b.y0 + (tile % a.tiles_y) * kTileY;
  if (x0 > b.x1 || y0 > b.y1) return;  // beyond this rotation's box: the whole block leaves
  __shared__ int32_t cx[kChunk], cy[kChunk];
  __shared__ float sums[kHaloX * kHaloY];
  int tx[kPerThread], ty[kPerThread];
  float acc[kPerThread];
  for (int j = 0; j < kPerThread; ++j) {
    const int i = threadIdx.x + j * kThreads;
    tx[j] = x0 - 1 + i / kHaloY;
    ty[j] = y0 - 1 + i % kHaloY;
    acc[j] = 0.0f;
  }
  const double c = a.cos_k[k], s = a.sin_k[k];
  const auto sx = static_cast<uint32_t>(a.size_x), sy = static_cast<uint32_t>(a.size_y);
  for (int start = 0; start < a.n; start += kChunk) {
    const int m = min(kChunk, a.n - start);
    rotate_chunk(a, c, s, start, m, cx, cy);
    __syncthreads();
    for (int i = 0; i < m; ++i) {
      const int32_t px = cx[i], py = cy[i];
      for (int j = 0; j < kPerThread; ++j) {  // sum_at_cells, in the same order
        const auto x = static_cast<uint32_t>(px + tx[j]), y = static_cast<uint32_t>(py + ty[j]);
        if (x < sx && y < sy) acc[j] += __ldg(a.field + (x * sy + y));  // < 2^26 cells (align.cc's limit)
      }
    }
    __syncthreads();
  }
  for (int j = 0; j < kPerThread; ++j) {
    const bool in_box = tx[j] >= b.x0 && tx[j] <= b.x1 && ty[j] >= b.y0 && ty[j] <= b.y1;
    sums[threadIdx.x + j * kThreads] = in_box ? acc[j] : -INFINITY;
  }
  __syncthreads();
  float block_best = -INFINITY;
  for (int i = threadIdx.x; i < kTileX * kTileY; i += kThreads) {
    const int ix = i / kTileY + 1, iy = i % kTileY + 1;
    const float v = sums[ix * kHaloY + iy];
    block_best = fmaxf(block_best, v);
    if (!(v > a.floor)) continue;
    bool peak = true;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy) peak = peak && !(sums[(ix + dx) * kHaloY + iy + dy] > v);
    if (!peak) continue;
    const unsigned int slot = atomicAdd(a.count, 1u);
    if (slot < static_cast<unsigned int>(a.capacity)) a.out[slot] = {k, x0 + ix - 1, y0 + iy - 1, v};
  }
  __syncthreads();  // sums[] is read no more: it holds the threads' bests
  report_best(block_best, sums, a.best);
}

}  // namespace

struct GpuLeafSearch::Device {
  cuda::DeviceBuffer<double> px, py, cos_k, sin_k;
  cuda::DeviceBuffer<TranslationBox> box;
  cuda::DeviceBuffer<float> field;
  cuda::DeviceBuffer<RawLeaf> out;
  cuda::DeviceBuffer<unsigned int> count;
  cuda::DeviceBuffer<int> best;
  Launch launch{};
  long long blocks = 0;
};

template <class T>
void upload(cuda::DeviceBuffer<T> &to, const T *from, size_t n) {
  to.resize(n);
  if (n > 0) VG_CUDA_CHECK(cudaMemcpy(to.get(), from, n * sizeof(T), cudaMemcpyHostToDevice));
}

GpuLeafSearch::GpuLeafSearch(const GpuLeafQuery &q) : d_(std::make_unique<Device>()) {
  Device &d = *d_;
  VG_CUDA_CHECK(cudaSetDevice(q.device));
  const size_t r = static_cast<size_t>(q.rotations);
  upload(d.px, q.px, static_cast<size_t>(q.n));
  upload(d.py, q.py, static_cast<size_t>(q.n));
  upload(d.cos_k, q.cos_k, r);
  upload(d.sin_k, q.sin_k, r);
  upload(d.box, q.box, r);
  upload(d.field, q.field, static_cast<size_t>(q.size_x) * static_cast<size_t>(q.size_y));
  d.out.resize(kCapacity);
  d.count.resize(1);
  d.best.resize(1);
  int widest_x = 1, widest_y = 1;
  for (size_t k = 0; k < r; ++k) {
    widest_x = std::max(widest_x, q.box[k].x1 - q.box[k].x0 + 1);
    widest_y = std::max(widest_y, q.box[k].y1 - q.box[k].y0 + 1);
  }
  const int tiles_y = (widest_y + kTileY - 1) / kTileY;
  const int tiles = ((widest_x + kTileX - 1) / kTileX) * tiles_y;
  d.blocks = static_cast<long long>(tiles) * q.rotations;
  if (d.blocks > 0x7fffffffLL) throw Error(ErrorCode::TooLarge, "align_maps: too many leaves for the GPU search");
  d.launch = Launch{d.px.get(), d.py.get(), q.n, q.c_x, q.c_y, q.h, d.cos_k.get(), d.sin_k.get(), d.box.get(),
                    tiles_y, tiles, d.field.get(), q.size_x, q.size_y, 0.0f, d.out.get(), d.count.get(),
                    kCapacity, d.best.get()};
}

GpuLeafSearch::~GpuLeafSearch() = default;

bool GpuLeafSearch::maxima(float floor, std::vector<Leaf> *out, float *best) {
  Device &d = *d_;
  out->clear();
  *best = -INFINITY;
  if (d.blocks == 0 || d.launch.n == 0) return true;
  const int lowest = INT_MIN;  // below ordered() of any float
  VG_CUDA_CHECK(cudaMemset(d.count.get(), 0, sizeof(unsigned int)));
  VG_CUDA_CHECK(cudaMemcpy(d.best.get(), &lowest, sizeof(int), cudaMemcpyHostToDevice));
  Launch a = d.launch;
  a.floor = floor;
  score_leaves<<<static_cast<unsigned int>(d.blocks), kThreads>>>(a);
  VG_CUDA_CHECK_LAUNCH();
  unsigned int count = 0;
  int best_bits = lowest;
  VG_CUDA_CHECK(cudaMemcpy(&count, d.count.get(), sizeof count, cudaMemcpyDeviceToHost));
  VG_CUDA_CHECK(cudaMemcpy(&best_bits, d.best.get(), sizeof best_bits, cudaMemcpyDeviceToHost));
  *best = from_ordered(best_bits);
  const size_t kept = std::min<size_t>(count, kCapacity);
  std::vector<RawLeaf> raw(kept);
  if (kept > 0) VG_CUDA_CHECK(cudaMemcpy(raw.data(), d.out.get(), kept * sizeof(RawLeaf), cudaMemcpyDeviceToHost));
  out->reserve(kept);
  for (const RawLeaf &l : raw) out->push_back(Leaf{l.rotation, l.tx, l.ty, l.sum});
  return count <= static_cast<unsigned int>(kCapacity);
}

}  // namespace align_detail
}  // namespace vasco
