#include "host_renderer.h"

#include <algorithm>

#include "huge_pages.h"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {

namespace {

HostGridRenderer::Box whole_grid(const GridGeometry &geo) { return {0, geo.size_x, 0, geo.size_y}; }

}  // namespace

// A grid of the same shape is reset lazily: the next apply from scan 0 writes
// every cell anyway (apply_to_reset), and only the cells an earlier render
// wrote need to become unknown.
void HostGridRenderer::reset(const GridGeometry &geo, const MapperParams &params) {
  const bool same_shape = geo.size_x == geo_.size_x && geo.size_y == geo_.size_y && cells_.size() == geo.num_cells();
  geo_ = geo;
  params_ = params;
  if (same_shape) {
    reset_pending_ = true;
    return;
  }
  assign_on_huge_pages(cells_, geo.num_cells(), -1.0f);  // keeps the allocation when the size does not grow
  reset_pending_ = false;
  written_ = Box{};
}

void HostGridRenderer::complete_reset() {
  if (!reset_pending_) return;
  fill_box(cells_.data(), geo_, written_, -1.0f);
  reset_pending_ = false;
  written_ = Box{};
}

void HostGridRenderer::apply(const ScanBatch &scans, size_t first, size_t last, MapStats *stats) {
  if (reset_pending_ && first == 0) {
    const Box stale = written_;
    written_ = whole_grid(geo_);  // until it returns: a render that throws leaves every cell stale
    written_ = apply_to_reset(scans, first, last, params_, geo_, stale, cells_.data(), stats);
    reset_pending_ = false;
    return;
  }
  complete_reset();
  written_ = whole_grid(geo_);
  apply_to(scans, first, last, params_, geo_, cells_.data(), stats);
}

HostGridRenderer::Box HostGridRenderer::apply_to_reset(const ScanBatch &scans, size_t first, size_t last,
                                                       const MapperParams &params, const GridGeometry &geo,
                                                       const Box &stale, float *cells, MapStats *stats) {
  fill_box(cells, geo, stale, -1.0f);
  apply_to(scans, first, last, params, geo, cells, stats);
  return whole_grid(geo);
}

void HostGridRenderer::fill_box(float *cells, const GridGeometry &geo, const Box &box, float value) {
  for (int x = box.x_lo; x < box.x_hi; ++x) {
    float *col = cells + egrid::cell_index(x, box.y_lo, geo.size_y);
    std::fill(col, col + box.height(), value);
  }
}

FinishedMap HostGridRenderer::finish(int downsample, int border) {
  complete_reset();
  return finish_grid(cells_.data(), geo_.size_x, geo_.size_y, geo_.resolution, downsample, border);
}

std::vector<float> HostGridRenderer::read(const GridWindow &w) {
  complete_reset();
  std::vector<float> out(static_cast<size_t>(w.width) * static_cast<size_t>(w.height));
  for (int x = 0; x < w.width; ++x) {
    const float *col = cells_.data() + egrid::cell_index(w.x0 + x, w.y0, geo_.size_y);
    std::copy(col, col + w.height, out.begin() + static_cast<size_t>(x) * w.height);
  }
  return out;
}

}  // namespace vasco
