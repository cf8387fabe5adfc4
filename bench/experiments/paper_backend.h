// paper_backend.h — the paper's kernel and its ablation variants as a
// one-shot Backend (float mode), for the benchmark's ablation table only: the
// library's CUDA backend runs our kernels.
#ifndef VASCO_BENCH_PAPER_BACKEND_H
#define VASCO_BENCH_PAPER_BACKEND_H

#include <memory>

#include "paper_kernels.h"
#include "vasco_gpu/backend.h"

namespace vasco {

// Throws std::runtime_error without a usable GPU.
std::unique_ptr<Backend> make_paper_backend(cuda::PaperVariant variant, int cuda_device = 0);

}  // namespace vasco

#endif  // VASCO_BENCH_PAPER_BACKEND_H
