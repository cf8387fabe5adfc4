// Exact mode's beam placement on the device (egrid_kernels.h says what and
// why): the beam angles per scan, the used beams' slots, their end cells,
// and the bound on their (tile, beam) pairs. Built with --fmad=false, as
// the other exact_*.cu: the end cell's arithmetic is the oracle's expression,
// each operation rounded on its own.

#include <cmath>

#include "cuda_check.h"
#include "egrid_kernels.h"
#include "exact_tile_bound.h"
#include "launch_shape.cuh"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace cuda {
namespace {

// One thread per scan: the oracle's angles are a running sum (beam 0's, then
// `step` added after every beam, skipped beams too), so each depends on the
// last one's rounding and the scan's beams are summed in order.
__global__ void angles_kernel(const ExactScan *scans, int num_scans, double *angles, uint32_t *scan_of) {
  const int s = blockIdx.x * blockDim.x + threadIdx.x;
  if (s >= num_scans) return;
  const ExactScan sc = scans[s];
  double angle = sc.angle0;
  for (int b = 0; b < sc.beam_count; ++b) {
    angles[sc.beam_begin + b] = angle;
    scan_of[sc.beam_begin + b] = static_cast<uint32_t>(s);
    angle += sc.step;
  }
}

__global__ void used_kernel(const float *ranges, size_t n, uint32_t *used) {
  const size_t i = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x;
  if (i < n) used[i] = egrid::is_beam_used(ranges[i]) ? 1u : 0u;
  if (i == n) used[n] = 0;
}

// The oracle's beam_end (oracle.h) with the device's cos and sin: true with
// the end cell where the truncation is sure to be the oracle's.
__device__ __forceinline__ bool sure_end_cell(const PlacementModel &m, const ExactScan &sc, double angle, float range,
                                              int *x2, int *y2) {
  double sn, cs;
  sincos(angle, &sn, &cs);
  const double r = range;
  const double vx = sc.lx + (r + m.wall) * cs / m.resolution;
  const double vy = sc.ly + (r + m.wall) * sn / m.resolution;
  const double tol = egrid::placement_tolerance(sc.lx, sc.ly, (r + m.wall) / m.resolution);
  if (!egrid::far_from_integers(vx, tol) || !egrid::far_from_integers(vy, tol)) return false;
  *x2 = static_cast<int>(vx);
  *y2 = static_cast<int>(vy);
  return true;
}

constexpr unsigned kPlaceThreads = 256;

__global__ void place_kernel(PlacementModel m, const ExactScan *scans, const float *ranges, const double *angles,
                             const uint32_t *scan_of, const uint32_t *slots, size_t n, PlacedBeam *beams,
                             UnsureBeam *unsure, uint32_t unsure_capacity, unsigned long long *counters) {
  __shared__ unsigned long long block_bound;
  if (threadIdx.x == 0) block_bound = 0;
  __syncthreads();
  const size_t i = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x;
  unsigned long long bound = 0;
  if (i < n && egrid::is_beam_used(ranges[i])) {
    const uint32_t s = scan_of[i], slot = slots[i];
    const ExactScan sc = scans[s];
    PlacedBeam b;
    b.scan = s;
    b.range = ranges[i];
    if (sure_end_cell(m, sc, angles[i], b.range, &b.x2, &b.y2)) {
      bound = beam_tile_bound(sc.x1, sc.y1, b.x2, b.y2, m.table_size);
    } else {
      b.x2 = b.y2 = 0;  // the host's fix follows
      bound = max_beam_tile_bound(m.table_size);
      const unsigned long long k = atomicAdd(&counters[1], 1ull);
      if (k < unsure_capacity) unsure[k] = UnsureBeam{slot, s, angles[i], b.range};
    }
    beams[slot] = b;
  }
  if (bound) atomicAdd(&block_bound, bound);
  __syncthreads();
  if (threadIdx.x == 0 && block_bound) atomicAdd(&counters[0], block_bound);
}

__global__ void fix_kernel(const BeamFix *fixes, size_t n, PlacedBeam *beams) {
  const size_t i = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const BeamFix f = fixes[i];
  beams[f.slot].x2 = f.x2;
  beams[f.slot].y2 = f.y2;
}

}  // namespace

void launch_exact_angles(const ExactScan *scans, int num_scans, double *angles, uint32_t *scan_of,
                         cudaStream_t stream) {
  if (num_scans <= 0) return;
  angles_kernel<<<blocks_for(static_cast<size_t>(num_scans), 64), 64, 0, stream>>>(scans, num_scans, angles,
                                                                                  scan_of);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_exact_used(const float *ranges, size_t num_beams, uint32_t *used, cudaStream_t stream) {
  used_kernel<<<blocks_for(num_beams + 1, 256), 256, 0, stream>>>(ranges, num_beams, used);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_exact_place(const PlacementModel &m, const ExactScan *scans, const float *ranges, const double *angles,
                        const uint32_t *scan_of, const uint32_t *slots, size_t num_beams, PlacedBeam *beams,
                        UnsureBeam *unsure, uint32_t unsure_capacity, unsigned long long *counters,
                        cudaStream_t stream) {
  if (num_beams == 0) return;
  place_kernel<<<blocks_for(num_beams, kPlaceThreads), kPlaceThreads, 0, stream>>>(
      m, scans, ranges, angles, scan_of, slots, num_beams, beams, unsure, unsure_capacity, counters);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_exact_fix(const BeamFix *fixes, size_t n, PlacedBeam *beams, cudaStream_t stream) {
  if (n == 0) return;
  fix_kernel<<<blocks_for(n, 128), 128, 0, stream>>>(fixes, n, beams);
  VG_CUDA_CHECK_LAUNCH();
}

}  // namespace cuda
}  // namespace vasco
