#include "host_renderer.h"

#include <algorithm>

#include "huge_pages.h"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {

namespace {

HostGridRenderer::Box whole_grid(const GridGeometry &geo) { return {0, geo.size_x, 0, geo.size_y}; }

// The cells from a box's first to its last (x-major): a range holding it.
HostGridRenderer::CellRange range_of(const GridGeometry &geo, const HostGridRenderer::Box &box) {
  if (box.cells() == 0) return {};
  return {static_cast<size_t>(egrid::cell_index(box.x_lo, box.y_lo, geo.size_y)),
          static_cast<size_t>(egrid::cell_index(box.x_hi - 1, box.y_hi, geo.size_y))};
}

// The smallest range holding both.
HostGridRenderer::CellRange hull(const HostGridRenderer::CellRange &a, const HostGridRenderer::CellRange &b) {
  if (a.lo >= a.hi) return b;
  if (b.lo >= b.hi) return a;
  return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)};
}

// The part of a range past the grid's n cells: the buffer's, not the grid's.
HostGridRenderer::CellRange beyond(const HostGridRenderer::CellRange &r, size_t n) {
  if (r.hi <= n) return {};
  return {std::max(r.lo, n), r.hi};
}

}  // namespace

// The reset is left to the next apply from scan 0, which writes every cell
// anyway (apply_to_reset): only the cells an earlier render may have written
// need to become unknown, in whatever shape the grid had. A grid that
// outgrows the buffer grows it, the new cells unknown: in place where the
// allocation has room, else in a new allocation, unknown from the start,
// with an eighth more room (re-renders after loop closures move the frame a
// little at a time; a new allocation of a large site's grid, faulted in
// again, cost more than the render's passes over it).
void HostGridRenderer::reset(const GridGeometry &geo, const MapperParams &params) {
  const size_t n = geo.num_cells();
  if (cells_.size() < n && cells_.capacity() >= n) {
    cells_.resize(n, -1.0f);
  } else if (cells_.size() < n) {
    // The old buffer is freed first: if the new one cannot be had, the
    // renderer is left with no grid (0 x 0), never a geometry past its buffer.
    written_ = CellRange{};
    reset_pending_ = false;
    geo_ = GridGeometry();  // 0 x 0
    assign_on_huge_pages(cells_, n, -1.0f, n + n / 8);
  }
  geo_ = geo;
  params_ = params;
  reset_pending_ = true;
}

void HostGridRenderer::complete_reset() {
  if (!reset_pending_) return;
  clear_outside(cells_.data(), geo_, written_, Box{});
  written_ = beyond(written_, geo_.num_cells());
  reset_pending_ = false;
}

void HostGridRenderer::apply(const ScanBatch &scans, size_t first, size_t last, MapStats *stats) {
  const size_t n = geo_.num_cells();
  if (reset_pending_ && first == 0) {
    const CellRange stale = written_;
    written_ = {0, cells_.size()};  // until it returns: a render that throws leaves every cell stale
    const Box box = apply_to_reset(scans, first, last, params_, geo_, stale, cells_.data(), stats);
    written_ = hull(range_of(geo_, box), beyond(stale, n));  // the buffer past the grid is left as it was
    reset_pending_ = false;
    return;
  }
  complete_reset();
  written_ = hull(written_, CellRange{0, n});
  apply_to(scans, first, last, params_, geo_, cells_.data(), stats);
}

HostGridRenderer::Box HostGridRenderer::apply_to_reset(const ScanBatch &scans, size_t first, size_t last,
                                                       const MapperParams &params, const GridGeometry &geo,
                                                       const CellRange &stale, float *cells, MapStats *stats) {
  clear_outside(cells, geo, stale, Box{});
  apply_to(scans, first, last, params, geo, cells, stats);
  return whole_grid(geo);
}

void HostGridRenderer::fill_box(float *cells, const GridGeometry &geo, const Box &box, float value) {
  for (int x = box.x_lo; x < box.x_hi; ++x) {
    float *col = cells + egrid::cell_index(x, box.y_lo, geo.size_y);
    std::fill(col, col + box.height(), value);
  }
}

// Column by column: a column's part of the range, less the box's rows.
void HostGridRenderer::clear_outside(float *cells, const GridGeometry &geo, const CellRange &stale, const Box &box) {
  const size_t n = geo.num_cells(), sy = static_cast<size_t>(geo.size_y);
  const size_t lo = std::min(stale.lo, n), hi = std::min(stale.hi, n);
  if (lo >= hi || sy == 0) return;
  for (size_t x = lo / sy; x * sy < hi; ++x) {
    const size_t y0 = std::max(lo, x * sy) - x * sy, y1 = std::min(hi, (x + 1) * sy) - x * sy;
    float *col = cells + x * sy;
    const bool crosses = box.cells() > 0 && x >= static_cast<size_t>(box.x_lo) && x < static_cast<size_t>(box.x_hi);
    if (!crosses) {
      std::fill(col + y0, col + y1, -1.0f);
      continue;
    }
    const size_t b0 = static_cast<size_t>(box.y_lo), b1 = static_cast<size_t>(box.y_hi);
    if (y0 < std::min(y1, b0)) std::fill(col + y0, col + std::min(y1, b0), -1.0f);
    if (std::max(y0, b1) < y1) std::fill(col + std::max(y0, b1), col + y1, -1.0f);
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
