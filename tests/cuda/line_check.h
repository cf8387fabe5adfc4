// line_check.h — runs the per-thread Bresenham forms against the sequential
// walk on the GPU (for tests).
#ifndef VASCO_CUDA_LINE_CHECK_H
#define VASCO_CUDA_LINE_CHECK_H

#include <cuda_runtime.h>

#include <cstdint>
#include <vector>

namespace vasco {
namespace cuda {

// Segments are (x1, y1, x2, y2) with |dx|, |dy| < 2^14. Returns the number
// of mismatches between the device's sequential walk and the closed forms;
// `hashes` receives a hash of each segment's walked cells.
unsigned long long check_lines_on_device(const std::vector<int4> &segments,
                                         std::vector<uint64_t> *hashes);

// The same hash of the host's walk.
uint64_t walk_hash_host(int x1, int y1, int x2, int y2);

}  // namespace cuda
}  // namespace vasco

#endif  // VASCO_CUDA_LINE_CHECK_H
