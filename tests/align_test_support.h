// Sessions of the bundled logs for the alignment's tests (align_logs_test,
// align_cuda_test): each mapped alone at the cell the alignment matches at.
#pragma once

#include "test_support.h"
#include "vasco_gpu/align.h"
#include "vasco_gpu/mapper.hpp"

namespace vasco::testing_support {

constexpr double kAlignCell = 0.1;

// Maps at 0.1 m directly (downsample 1): the cell the alignment matches at,
// and quick enough to map a session per seed.
inline MapperParams params_at_align_cell() {
  MapperParams p;
  p.resolution = kAlignCell;
  p.downsample = 1;
  p.border = 5;
  return p;
}

inline AlignMap align_map_of_scans(const ScanBatch &scans) {
  BackendOptions options;
  options.threads = 2;
  Mapper m(params_at_align_cell(), "cpu_threads", options);
  m.insert(scans);
  return align_map_of(m.finish(), m.frame());
}

}  // namespace vasco::testing_support
