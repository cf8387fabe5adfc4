// Sessions of the bundled logs for the alignment's tests (align_logs_test,
// align_cuda_test): each mapped alone at the cell the alignment matches at.
#pragma once

#include <algorithm>
#include <cmath>

#include "test_support.h"
#include "vasco_gpu/align.h"
#include "vasco_gpu/mapper.hpp"

namespace vasco::testing_support {

constexpr double kAlignCell = 0.1;

// A wall of a drawn floor plan, and a point's distance to it.
struct Segment {
  double x0, y0, x1, y1;
};

inline double distance_to(const Segment &s, double x, double y) {
  const double dx = s.x1 - s.x0, dy = s.y1 - s.y0;
  const double len2 = dx * dx + dy * dy;
  const double u = len2 > 0 ? std::clamp(((x - s.x0) * dx + (y - s.y0) * dy) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(x - (s.x0 + u * dx), y - (s.y0 + u * dy));
}

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
