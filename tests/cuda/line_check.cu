// A check of the per-thread (closed-form) Bresenham forms on the GPU: for
// each segment, the device's sequential walk (egrid_math.h, the oracle's
// walker) is compared cell by cell with the float mode's closed form
// (line_cell) and the exact mode's membership test (step_of_cell); a hash of
// the walked cells lets the host compare the device walk with its own.
#include "cuda_check.h"
#include "line_check.h"
#include "line_rec.cuh"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace cuda {
namespace {

__global__ void line_check_kernel(const int4 *segs, size_t n, unsigned long long *mismatches,
                                  uint64_t *hashes) {
  const size_t s = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x;
  if (s >= n) return;
  const int4 g = segs[s];
  egrid::BresenhamLine line;
  egrid::bresenham_init(line, g.x, g.y, g.z, g.w);
  const egrid::LineParams p = egrid::line_params(g.x, g.y, g.z, g.w);
  // A table large enough for the whole segment, so k_max is its last step.
  const LineRec L = make_line(g.x, g.y, g.z, g.w, 1.0f, 1 << 30);
  uint64_t h = 1469598103934665603ull;
  unsigned bad = 0;
  int k = 0;
  do {
    int cx, cy;
    egrid::bresenham_current(line, &cx, &cy);
    h = (h ^ static_cast<uint32_t>(cx)) * 1099511628211ull;
    h = (h ^ static_cast<uint32_t>(cy)) * 1099511628211ull;
    int fx, fy;
    egrid::line_cell(p, k, &fx, &fy);
    if (fx != cx || fy != cy) ++bad;
    if (step_of_cell(L, cx, cy) != k) ++bad;
    // The cell beside it (across the minor axis) is not on the line.
    if (step_of_cell(L, cx + (p.steep ? 1 : 0), cy + (p.steep ? 0 : 1)) >= 0) ++bad;
    ++k;
  } while (egrid::bresenham_next(line));
  if (k != p.major_len + 1) ++bad;
  hashes[s] = h;
  if (bad) atomicAdd(mismatches, static_cast<unsigned long long>(bad));
}

}  // namespace

uint64_t walk_hash_host(int x1, int y1, int x2, int y2) {
  egrid::BresenhamLine line;
  egrid::bresenham_init(line, x1, y1, x2, y2);
  uint64_t h = 1469598103934665603ull;
  do {
    int cx, cy;
    egrid::bresenham_current(line, &cx, &cy);
    h = (h ^ static_cast<uint32_t>(cx)) * 1099511628211ull;
    h = (h ^ static_cast<uint32_t>(cy)) * 1099511628211ull;
  } while (egrid::bresenham_next(line));
  return h;
}

unsigned long long check_lines_on_device(const std::vector<int4> &segments,
                                         std::vector<uint64_t> *hashes) {
  const size_t n = segments.size();
  DeviceBuffer<int4> d_segs(n);
  DeviceBuffer<unsigned long long> d_bad(1);
  DeviceBuffer<uint64_t> d_hash(n);
  VG_CUDA_CHECK(cudaMemcpy(d_segs.get(), segments.data(), n * sizeof(int4), cudaMemcpyHostToDevice));
  VG_CUDA_CHECK(cudaMemset(d_bad.get(), 0, sizeof(unsigned long long)));
  if (n) {
    line_check_kernel<<<static_cast<unsigned>((n + 255) / 256), 256>>>(d_segs.get(), n, d_bad.get(),
                                                                       d_hash.get());
    VG_CUDA_CHECK_LAUNCH();
  }
  unsigned long long bad = 0;
  VG_CUDA_CHECK(cudaMemcpy(&bad, d_bad.get(), sizeof bad, cudaMemcpyDeviceToHost));
  hashes->resize(n);
  VG_CUDA_CHECK(cudaMemcpy(hashes->data(), d_hash.get(), n * sizeof(uint64_t), cudaMemcpyDeviceToHost));
  return bad;
}

}  // namespace cuda
}  // namespace vasco
