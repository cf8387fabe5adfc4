#include "host_renderer.h"

#include <algorithm>

#include "huge_pages.h"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {

void HostGridRenderer::reset(const GridGeometry &geo, const MapperParams &params) {
  geo_ = geo;
  params_ = params;
  assign_on_huge_pages(cells_, geo.num_cells(), -1.0f);  // keeps the allocation when the size does not grow
}

void HostGridRenderer::apply(const ScanBatch &scans, size_t first, size_t last, MapStats *stats) {
  apply_to(scans, first, last, params_, geo_, cells_.data(), stats);
}

FinishedMap HostGridRenderer::finish(int downsample, int border) {
  return finish_grid(cells_.data(), geo_.size_x, geo_.size_y, geo_.resolution, downsample, border);
}

std::vector<float> HostGridRenderer::read(const GridWindow &w) {
  std::vector<float> out(static_cast<size_t>(w.width) * static_cast<size_t>(w.height));
  for (int x = 0; x < w.width; ++x) {
    const float *col = cells_.data() + egrid::cell_index(w.x0 + x, w.y0, geo_.size_y);
    std::copy(col, col + w.height, out.begin() + static_cast<size_t>(x) * w.height);
  }
  return out;
}

}  // namespace vasco
