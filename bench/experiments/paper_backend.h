// paper_backend.h — the paper's kernel and its ablation variants as a
// one-shot mapper (float mode), for the benchmark's ablation table only: the
// library's CUDA backend runs our kernels.
#ifndef VASCO_BENCH_PAPER_BACKEND_H
#define VASCO_BENCH_PAPER_BACKEND_H

#include <memory>
#include <string>
#include <vector>

#include "paper_kernels.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/renderer.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

// Maps a whole batch on a fresh grid, as the paper's working cycle does
// (upload once, every scan, download once): no session, no apply.
class PaperMapper {
 public:
  virtual ~PaperMapper() = default;
  virtual std::string name() const = 0;
  virtual std::vector<float> map(const ScanBatch &batch, const MapperParams &params, const GridGeometry &geo,
                                 MapStats *stats) = 0;
};

// Throws std::runtime_error without a usable GPU.
std::unique_ptr<PaperMapper> make_paper_mapper(cuda::PaperVariant variant, int cuda_device = 0);

}  // namespace vasco

#endif  // VASCO_BENCH_PAPER_BACKEND_H
