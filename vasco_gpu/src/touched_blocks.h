// touched_blocks.h — which blocks of a render's box its scans can reach, so
// that a per-cell scratch over the box (cpu_float's sums) is cleared and
// merged only there. A box is the union of the scans' reach squares; at a
// large site it is the whole grid, while a robot's loop reaches a ring of it
// (bench/large_site_bench.py: clearing and merging the sums over a 4·10^8-cell
// box took 0.33 s a render, which grows with the box, not with the updates).
// Internal to the library.
#ifndef VASCO_GPU_SRC_TOUCHED_BLOCKS_H
#define VASCO_GPU_SRC_TOUCHED_BLOCKS_H

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "beam_updates.h"

namespace vasco {

class TouchedBlocks {
 public:
  // Blocks of kSide x kSide cells: a column's part of a block is 256 bytes
  // of float sums, and a scan of 10 m range at 5 cm marks some 50 blocks.
  static constexpr int kSide = 64;

  // No block marked, over `box` (box-relative cells from here on).
  void reset(const beam_updates::Box &box) {
    width_ = box.width(), height_ = box.height();
    bw_ = (width_ + kSide - 1) / kSide, bh_ = (height_ + kSide - 1) / kSide;
    marked_.assign(static_cast<size_t>(bw_) * static_cast<size_t>(bh_), 0);
  }

  // Marks the blocks of the cells [x0, x1] x [y0, y1] (box-relative,
  // clipped to the box).
  void mark(int64_t x0, int64_t x1, int64_t y0, int64_t y1) {
    x0 = std::max<int64_t>(x0, 0), y0 = std::max<int64_t>(y0, 0);
    x1 = std::min<int64_t>(x1, width_ - 1), y1 = std::min<int64_t>(y1, height_ - 1);
    if (x0 > x1 || y0 > y1) return;
    for (int64_t bx = x0 / kSide; bx <= x1 / kSide; ++bx)
      std::fill_n(marked_.begin() + bx * bh_ + y0 / kSide, y1 / kSide - y0 / kSide + 1, 1);
  }

  // Calls f(x, y_begin, y_end) for each column x's run of marked cells:
  // [y_begin, y_end), box-relative; adjacent marked blocks of a column of
  // blocks make one run.
  template <class F>
  void for_each_run(F &&f) const {
    for (int bx = 0; bx < bw_; ++bx) {
      const unsigned char *col = marked_.data() + static_cast<size_t>(bx) * bh_;
      for (int by = 0; by < bh_;) {
        if (!col[by]) {
          ++by;
          continue;
        }
        int end = by;
        while (end < bh_ && col[end]) ++end;
        const int y0 = by * kSide, y1 = std::min(end * kSide, height_);
        for (int x = bx * kSide; x < std::min((bx + 1) * kSide, width_); ++x) f(x, y0, y1);
        by = end;
      }
    }
  }

  // The cells the marked blocks hold.
  size_t cells() const {
    size_t n = 0;
    for_each_run([&](int, int y0, int y1) { n += static_cast<size_t>(y1 - y0); });
    return n;
  }

 private:
  int width_ = 0, height_ = 0, bw_ = 0, bh_ = 0;
  std::vector<unsigned char> marked_;  // [bx][by]
};

}  // namespace vasco

#endif  // VASCO_GPU_SRC_TOUCHED_BLOCKS_H
