// Exact mode's beam placement on the device (egrid_kernels.h says what and
// why): the used beams' slots, then per scan its beams' angles, their end
// cells, and the bound on their (tile, beam) pairs. Built with --fmad=false, as
// the other exact_*.cu: the end cell's arithmetic is the oracle's expression,
// each operation rounded on its own.

#include <cmath>

#include "cuda_check.h"
#include "egrid_kernels.h"
#include "exact_tile_bound.h"
#include "launch_shape.cuh"
#include "warp_sum.cuh"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace cuda {
namespace {

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

// A warp per scan. The oracle's angles are a running sum (beam 0's, then
// `step` added after every beam, skipped beams too), so each depends on the
// last one's rounding: every lane runs the scan's whole sum, the same
// additions in the same order, and keeps the angle of each 32nd beam, its
// own. (A thread per scan writing every angle out for a second kernel took
// 77 us of fr079's re-render on an H100, its stores 32 lines apart.)
constexpr unsigned kPlaceThreads = 256;
constexpr unsigned kScansPerBlock = kPlaceThreads / 32;

__global__ void place_kernel(PlacementModel m, const ExactScan *scans, int num_scans, const float *ranges,
                             const uint32_t *slots, PlacedBeam *beams, UnsureBeam *unsure,
                             uint32_t unsure_capacity, unsigned long long *counters) {
  const int s = blockIdx.x * kScansPerBlock + threadIdx.x / 32;
  const int lane = threadIdx.x & 31;
  if (s >= num_scans) return;  // the whole warp
  const ExactScan sc = scans[s];
  unsigned long long bound = 0;
  double angle = sc.angle0;
  for (int b0 = 0; b0 < sc.beam_count; b0 += 32) {
    double mine = 0;
#pragma unroll
    for (int j = 0; j < 32; ++j) {
      if (j == lane) mine = angle;
      angle += sc.step;
    }
    const int b = b0 + lane;
    if (b >= sc.beam_count) continue;
    const size_t i = static_cast<size_t>(sc.beam_begin) + b;
    if (!egrid::is_beam_used(ranges[i])) continue;
    const uint32_t slot = slots[i];
    PlacedBeam pb;
    pb.scan = static_cast<uint32_t>(s);
    pb.range = ranges[i];
    if (sure_end_cell(m, sc, mine, pb.range, &pb.x2, &pb.y2)) {
      bound += beam_tile_bound(sc.x1, sc.y1, pb.x2, pb.y2, m.table_size);
    } else {
      pb.x2 = pb.y2 = 0;  // the host's fix follows
      bound += max_beam_tile_bound(m.table_size);
      const unsigned long long k = atomicAdd(&counters[1], 1ull);
      if (k < unsure_capacity) unsure[k] = UnsureBeam{slot, static_cast<uint32_t>(s), mine, pb.range};
    }
    beams[slot] = pb;
  }
  bound = warp_sum(bound);
  if (lane == 0 && bound) atomicAdd(&counters[0], bound);
}

__global__ void fix_kernel(const BeamFix *fixes, size_t n, PlacedBeam *beams) {
  const size_t i = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const BeamFix f = fixes[i];
  beams[f.slot].x2 = f.x2;
  beams[f.slot].y2 = f.y2;
}

}  // namespace

void launch_exact_used(const float *ranges, size_t num_beams, uint32_t *used, cudaStream_t stream) {
  used_kernel<<<blocks_for(num_beams + 1, 256), 256, 0, stream>>>(ranges, num_beams, used);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_exact_place(const PlacementModel &m, const ExactScan *scans, int num_scans, const float *ranges,
                        const uint32_t *slots, PlacedBeam *beams, UnsureBeam *unsure, uint32_t unsure_capacity,
                        unsigned long long *counters, cudaStream_t stream) {
  if (num_scans <= 0) return;
  place_kernel<<<blocks_for(static_cast<size_t>(num_scans), kScansPerBlock), kPlaceThreads, 0, stream>>>(
      m, scans, num_scans, ranges, slots, beams, unsure, unsure_capacity, counters);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_exact_fix(const BeamFix *fixes, size_t n, PlacedBeam *beams, cudaStream_t stream) {
  if (n == 0) return;
  fix_kernel<<<blocks_for(n, 128), 128, 0, stream>>>(fixes, n, beams);
  VG_CUDA_CHECK_LAUNCH();
}

}  // namespace cuda
}  // namespace vasco
