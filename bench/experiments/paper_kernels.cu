// The paper's kernel ("Fast Processing of Grid Maps using Graphical
// Multiprocessors"), kept as a baseline for the benchmarks: one launch per
// scan, one block per beam, one thread per cell of the beam, the beam's data
// in shared memory, the parameters in constant memory. Unlike the paper's, it
// loses no update: cells are accumulated in log-odds with atomic adds, as in
// float mode (float_kernels.cu), so its maps equal float mode's up to the
// order of float additions.
//
// Variants, for the ablation of the paper's design choices on today's GPU:
//   PerScan         all of the above
//   PerScanNoShared every thread reads the beam's data from global memory
//                   and places the beam itself
//   PerScanNoConst  parameters read from global memory, not constant memory
//   Fused           the PerScan kernel, but all scans in one launch
#include <algorithm>

#include "cuda_check.h"
#include "paper_kernels.h"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace cuda {
namespace {

__constant__ KernelModel<float> c_model;

struct BeamShared {
  int x1, y1, k_end;
  float r;
  egrid::LineParams p;
  bool used, closed;
};

__device__ __forceinline__ void place_beam(const KernelModel<float> &m, const FloatScan &sc, int b,
                                           const float *ranges, BeamShared *out) {
  const float r = ranges[sc.beam_begin + b];
  out->used = r < 50.0f;
  out->r = r;
  out->x1 = sc.x1;
  out->y1 = sc.y1;
  if (!out->used) return;
  float sn, cs;
  sincosf(sc.theta + sc.first + static_cast<float>(b) * sc.step, &sn, &cs);
  const int x2 = egrid::trunc_to_int(sc.lx + (r + m.wall) * cs / m.resolution);
  const int y2 = egrid::trunc_to_int(sc.ly + (r + m.wall) * sn / m.resolution);
  out->closed = egrid::is_closed_form_line(sc.x1, sc.y1, x2, y2);
  if (!out->closed) return;  // degenerate beam (-inf range): dropped by this baseline
  out->p = egrid::line_params(sc.x1, sc.y1, x2, y2);
  out->k_end = min(out->p.major_len, m.table_size - 1);
}

__device__ __forceinline__ void update_cell(const KernelModel<float> &m, const BeamShared &B, int k,
                                            float *logodds, uint8_t *touched) {
  int cx, cy;
  egrid::line_cell(B.p, k, &cx, &cy);
  if (cx < 0 || cx >= m.size_x || cy < 0 || cy >= m.size_y) return;
  const int i = abs(cx - B.x1), j = abs(cy - B.y1);
  const float d = sqrtf(static_cast<float>(i * i + j * j)) * m.resolution;
    float p;
  if (!egrid::sensor_model(m.sensor, d, B.r, &p)) return;
  const size_t c = static_cast<size_t>(cx) * m.size_y + cy;
  atomicAdd(logodds + c, __logf(p / (1.0f - p)) - m.logodds_prior);
  touched[c] = 1;
}

// Block per beam of one scan (scan_base + blockIdx.y selects the scan when fused).
template <bool kShared, bool kConst>
__global__ void paper_kernel(const KernelModel<float> *g_model, const FloatScan *scans, int scan_base,
                             const float *ranges, float *logodds, uint8_t *touched) {
  const KernelModel<float> &m = kConst ? c_model : *g_model;
  const FloatScan &sc = scans[scan_base + blockIdx.y];
  const int b = blockIdx.x;
  if (b >= sc.beam_count) return;
  __shared__ BeamShared sh;
  BeamShared local;
  const BeamShared *B;
  if (kShared) {
    if (threadIdx.x == 0) place_beam(m, sc, b, ranges, &sh);
    __syncthreads();
    B = &sh;
  } else {
    place_beam(m, sc, b, ranges, &local);
    B = &local;
  }
  if (!B->used || !B->closed) return;
  for (int k = threadIdx.x; k <= B->k_end; k += blockDim.x) update_cell(m, *B, k, logodds, touched);
}

}  // namespace

const char *paper_variant_name(PaperVariant v) {
  switch (v) {
    case PaperVariant::PerScan: return "paper: scan/launch, shared, const";
    case PaperVariant::PerScanNoShared: return "paper: scan/launch, no shared";
    case PaperVariant::PerScanNoConst: return "paper: scan/launch, no const";
    case PaperVariant::Fused: return "paper: fused launch, shared, const";
    case PaperVariant::FloorRegisters: return "ours: floor, updates to registers";
    case PaperVariant::FloorSharedTile: return "ours: floor, updates to a shared tile";
  }
  return "?";
}

void run_paper_variant(PaperVariant v, const KernelModel<float> &m, const KernelModel<float> *d_model,
                       const FloatScan *h_scans, const FloatScan *d_scans, int num_scans,
                       const float *d_ranges, float *d_logodds, uint8_t *d_touched,
                       cudaStream_t stream) {
  if (num_scans <= 0) return;
  VG_CUDA_CHECK(cudaMemcpyToSymbolAsync(c_model, &m, sizeof m, 0, cudaMemcpyHostToDevice, stream));
  // A thread per cell of the beam: as many threads as the distance table is
  // long (the walk is cut there), in whole warps, at most 1024.
  const int threads = std::min(1024, std::max(32, (m.table_size + 31) / 32 * 32));
  if (v == PaperVariant::Fused) {
    int max_beams = 0;
    for (int s = 0; s < num_scans; ++s) max_beams = std::max(max_beams, h_scans[s].beam_count);
    // gridDim.y is limited to 65535: launch in slices of scans.
    for (int base = 0; base < num_scans; base += 65535) {
      const int n = std::min(65535, num_scans - base);
      paper_kernel<true, true><<<dim3(std::max(1, max_beams), n), threads, 0, stream>>>(
          d_model, d_scans, base, d_ranges, d_logodds, d_touched);
      VG_CUDA_CHECK_LAUNCH();
    }
    return;
  }
  for (int s = 0; s < num_scans; ++s) {
    const int beams = h_scans[s].beam_count;
    if (beams <= 0) continue;
    switch (v) {
      case PaperVariant::PerScan:
        paper_kernel<true, true><<<beams, threads, 0, stream>>>(d_model, d_scans, s, d_ranges,
                                                                 d_logodds, d_touched);
        break;
      case PaperVariant::PerScanNoShared:
        paper_kernel<false, true><<<beams, threads, 0, stream>>>(d_model, d_scans, s, d_ranges,
                                                                  d_logodds, d_touched);
        break;
      case PaperVariant::PerScanNoConst:
        paper_kernel<true, false><<<beams, threads, 0, stream>>>(d_model, d_scans, s, d_ranges,
                                                                  d_logodds, d_touched);
        break;
      default:
        break;
    }
    VG_CUDA_CHECK_LAUNCH();
  }
}

}  // namespace cuda
}  // namespace vasco
