// align_gpu.h — the global search of the alignment on the GPU: instead of
// branch and bound, every leaf (rotation, translation in whole cells) of the
// coarse search space is scored, a CUDA block per tile of translations of
// one rotation. The sums are branch_and_bound's to the bit: the points'
// cells are rotated with the CPU's cos and sin and its operations rounded
// one by one (align_score.h's rotated_cells), and each leaf's float sum
// adds the points in index order as sum_at_cells does. The leaves that are
// local maxima over their eight neighbours come back to the host, which
// keeps the best distinct ones as branch_and_bound does.
#ifndef VASCO_GPU_SRC_ALIGN_ALIGN_GPU_H
#define VASCO_GPU_SRC_ALIGN_ALIGN_GPU_H

#include <memory>
#include <string>
#include <vector>

#include "align_search.h"

namespace vasco {
namespace align_detail {

// Whether this build has the GPU search (a CUDA build); a usable device is
// align.cc's question (gpu_usable).
bool gpu_search_compiled();

// branch_and_bound's result (align_search.h) for `space`, found on the GPU:
// the `keep` best distinct leaves whose sums beat `floor_sum`, best first,
// scored on pooled level 0 (the field), on CUDA device `device`. Where the local maxima beat the
// device's list even at nine tenths of the best sum (no real map comes
// near), branch_and_bound on `threads` threads answers instead. Throws
// vasco::Error (NoGpu, OutOfMemory, Internal) when the device fails; a build
// without CUDA throws NoGpu.
std::vector<Leaf> gpu_search(const SearchSpace &space, float floor_sum, int keep, const Distinctness &distinct,
                             int threads, int device);

// The device side (align_search.cu, CUDA builds only).
struct GpuLeafQuery {
  const double *px = nullptr, *py = nullptr;  // the moving points, metres
  int n = 0;
  double c_x = 0, c_y = 0, h = 0;             // SearchSpace's centroid and cell
  const double *cos_k = nullptr, *sin_k = nullptr;  // per rotation, the host's std::cos and std::sin
  const TranslationBox *box = nullptr;        // per rotation
  int rotations = 0;
  const float *field = nullptr;               // x-major, 0 outside
  int size_x = 0, size_y = 0;
  int device = 0;                             // the CUDA device it runs on
};

// Scores every leaf of a query on the device. Its memory is allocated once,
// at construction; each maxima() call scores every leaf again.
class GpuLeafSearch {
 public:
  explicit GpuLeafSearch(const GpuLeafQuery &q);
  ~GpuLeafSearch();
  GpuLeafSearch(const GpuLeafSearch &) = delete;
  GpuLeafSearch &operator=(const GpuLeafSearch &) = delete;
  // The leaves whose sums beat `floor` and are at least each neighbour's in
  // the box (x and y within one cell, the same rotation), in no order; false
  // when there are more than the capacity (the list then holds some of
  // them). `best` gets the highest sum of any leaf.
  bool maxima(float floor, std::vector<Leaf> *out, float *best);
  // How many leaves maxima() can return.
  static constexpr int kCapacity = 1 << 20;

 private:
  struct Device;
  std::unique_ptr<Device> d_;
};

}  // namespace align_detail
}  // namespace vasco

#endif  // VASCO_GPU_SRC_ALIGN_ALIGN_GPU_H
