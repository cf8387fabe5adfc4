// Exact mode's tables (exact_cells.cuh): per (i, j) offset of a cell from
// a beam's start cell, the free and occupied odds factors, and per i the
// first j where a beam stops. Built with --fmad=false, as every exact kernel.

#include "cuda_check.h"
#include "egrid_kernels.h"
#include "launch_shape.cuh"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace cuda {
namespace {

__global__ void tables_kernel(KernelModel<double> m, double2 *factors) {
  const int n = m.table_size * m.table_size;
    for (int idx = blockIdx.x * blockDim.x + threadIdx.x; idx < n; idx += gridDim.x * blockDim.x) {
    const int i = idx / m.table_size, j = idx % m.table_size;
    double ff, fo;
    egrid::odds_factors_at(m.sensor, egrid::cell_distance(i, j, m.resolution), &ff, &fo);
    factors[idx] = make_double2(ff, fo);
  }
}

// reach[i] = the first j where the beam stops (distance(i, j) >= max_range;
// table_size if none). For tables of at most 2^11 entries per axis i*i + j*j cannot wrap, so
// the distance grows with j and "an update at (i, j)" is exactly j < reach[i].
__global__ void reach_kernel(KernelModel<double> m, int *reach) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= m.table_size) return;
  int j = 0;
  while (j < m.table_size && !egrid::stops_beam(m.sensor, egrid::cell_distance(i, j, m.resolution))) ++j;
  reach[i] = j;
}

}  // namespace

void launch_exact_tables(const KernelModel<double> &m, double2 *factors, int *reach, cudaStream_t stream) {
  const size_t n = static_cast<size_t>(m.table_size) * m.table_size;
  if (n == 0) return;
  tables_kernel<<<min(blocks_for(n, 256), 4096u), 256, 0, stream>>>(m, factors);
  VG_CUDA_CHECK_LAUNCH();
  reach_kernel<<<blocks_for(static_cast<size_t>(m.table_size), 128), 128, 0, stream>>>(m, reach);
  VG_CUDA_CHECK_LAUNCH();
}

}  // namespace cuda
}  // namespace vasco
