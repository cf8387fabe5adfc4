// paper_kernels.h — the paper's kernel and its ablation variants (baselines
// for the benchmarks; see paper_kernels.cu).
#ifndef VASCO_CUDA_PAPER_KERNELS_H
#define VASCO_CUDA_PAPER_KERNELS_H

#include <cuda_runtime.h>

#include "egrid_kernels.h"

namespace vasco {
namespace cuda {

// The paper's kernel and its ablation; then the floors of our float kernel's
// accumulation (egrid_kernels.h FloatFloor: the map comes out wrong).
enum class PaperVariant { PerScan, PerScanNoShared, PerScanNoConst, Fused, FloorRegisters, FloorSharedTile };
const char *paper_variant_name(PaperVariant v);

// Accumulates every scan into d_logodds / d_touched like launch_float_map.
// h_scans is the host copy of d_scans (per-scan launches need the counts);
// d_model is a device copy of m (for the variant without constant memory).
void run_paper_variant(PaperVariant v, const KernelModel<float> &m, const KernelModel<float> *d_model,
                       const FloatScan *h_scans, const FloatScan *d_scans, int num_scans,
                       const float *d_ranges, float *d_logodds, uint8_t *d_touched,
                       cudaStream_t stream);

}  // namespace cuda
}  // namespace vasco

#endif  // VASCO_CUDA_PAPER_KERNELS_H
