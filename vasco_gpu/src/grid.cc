#include "vasco_gpu/grid.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "vasco_gpu/error.h"
#include "vasco_gpu/internal/finish_math.h"
#include "vasco_gpu/internal/oracle.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

void PoseExtent::add(const ScanBatch &batch, size_t first, size_t last) {
  for (size_t s = first; s < last; ++s) add_pose(batch.x[s], batch.y[s], batch.theta[s], s);
}

void PoseExtent::add_pose(double x, double y, double theta, size_t index) {
  if (scans++ == 0) {
    x0 = x;
    y0 = y;
    theta0 = theta;
  }
  const double dx = std::fabs(x - x0), dy = std::fabs(y - y0);
  if (dx > mx) mx = dx, far_x = index;
  if (dy > my) my = dy, far_y = index;
}

oracle::GridFrame start_frame(const GridGeometry &geo, const ScanBatch &batch) {
  oracle::GridFrame frame;
  frame.size_x = geo.size_x;
  frame.size_y = geo.size_y;
  frame.resolution = geo.resolution;
  frame.theta_offset = geo.theta_offset;
  if (geo.centre_given)
    oracle::scan_start(frame, geo.x0, geo.y0, geo.theta_offset);  // records the pose as a first update would
  else if (batch.num_scans() > 0)
    oracle::scan_start(frame, batch.x[0], batch.y[0], batch.theta[0]);
  return frame;
}

std::string pose_span_text(const PoseExtent &e, const ScanBatch &batch) {
  auto line = [&](size_t s) { return s < batch.line.size() ? batch.line[s] : static_cast<long>(s); };
  std::ostringstream msg;
  msg << "the poses span " << 2 * e.mx << " m x " << 2 * e.my << " m (from the scan at line " << line(0)
      << " to line " << line(e.far_x) << " in x and line " << line(e.far_y) << " in y)";
  return msg.str();
}

GridGeometry size_grid(const ScanBatch &batch, const MapperParams &params) {
  PoseExtent e;
  e.add(batch, 0, batch.num_scans());
  return size_grid(e, batch, params);
}

GridGeometry size_grid(const PoseExtent &e, const ScanBatch &batch, const MapperParams &params) {
  if (e.scans == 0) throw Error(ErrorCode::BadInput, "no laser scans to map");
  GridGeometry g;
  g.resolution = params.resolution;
  g.x0 = e.x0;
  g.y0 = e.y0;
  g.theta_offset = e.theta0;
  const double reach = params.range_max + params.resolution;
  const double mx = e.mx + reach, my = e.my + reach;
  const double half_x = std::ceil(mx / params.resolution);
  const double half_y = std::ceil(my / params.resolution);
  const double sx = 2 * half_x + 2, sy = 2 * half_y + 2;
  // No cap on the cells (the memory they need is the Mapper's check); a side
  // must stay an int with room for the kernels' rounding (kMaxGridSide).
  if (!(sx <= static_cast<double>(kMaxGridSide)) || !(sy <= static_cast<double>(kMaxGridSide))) {
    std::ostringstream msg;
    msg << pose_span_text(e, batch) << ": a grid of " << sx << " x " << sy << " cells at " << params.resolution
        << " m is too large (each side at most " << kMaxGridSide
        << " cells); check the poses or raise vasco_resolution";
    throw Error(ErrorCode::TooLarge, msg.str());
  }
  g.size_x = static_cast<int>(sx);
  g.size_y = static_cast<int>(sy);
  return g;
}

namespace {

// CARMEN's finish (finish_math.h, the same functions the GPU's finish
// kernels run): block means, the known box, the crop and its cells. The
// grid comes `strip_blocks` block columns at a time: strip(x0, width) gives
// columns [x0, x0 + width), x-major. Each block reads the cells of its own
// columns in CARMEN's order, wherever they are: the same bytes however the
// grid is cut into strips.
template <class Strip>
FinishedMap finish_strips(Strip &&strip, int size_x, int size_y, double resolution, int downsample, int border,
                          int strip_blocks) {
  finish::check_arguments(downsample, border);
  const finish::Blocks blocks = finish::blocks_of(size_x, size_y, downsample);
  std::vector<float> means(static_cast<size_t>(blocks.count()));
  finish::KnownBox known;
  for (int bx0 = 0; bx0 < blocks.nx; bx0 += strip_blocks) {
    const int nb = std::min(strip_blocks, blocks.nx - bx0);
    const int64_t x0 = static_cast<int64_t>(bx0) * downsample;  // < size_x
    const float *cells = strip(static_cast<int>(x0), static_cast<int>(static_cast<int64_t>(nb) * downsample));
    const int64_t origin = x0 * size_y;  // the strip's first cell in the grid
    const auto cell_at = [cells, origin](int64_t c) { return cells[c - origin]; };
    for (int bx = bx0; bx < bx0 + nb; ++bx) {
      for (int by = 0; by < blocks.ny; ++by) {
        const finish::BlockMean m = finish::block_mean(cell_at, size_y, downsample, bx, by);
        if (m.known) finish::widen(known, bx, by);
        means[static_cast<size_t>(bx) * blocks.ny + by] = m.value;
      }
    }
  }
  const finish::Crop crop = finish::crop_of(known, blocks, border);
  FinishedMap m = finish::finished_frame(crop, resolution, downsample);
  m.cells.resize(static_cast<size_t>(crop.count()));
  for (int x = 0; x < crop.size_x; ++x)
    for (int y = 0; y < crop.size_y; ++y)
      m.cells[static_cast<size_t>(x) * crop.size_y + y] = means[finish::cropped_block(crop, blocks, x, y)];
  return m;
}

}  // namespace

FinishedMap finish_grid(const float *cells, int size_x, int size_y, double resolution,
                        int downsample, int border) {
  const auto whole = [cells, size_y](int x0, int) { return cells + static_cast<int64_t>(x0) * size_y; };
  return finish_strips(whole, size_x, size_y, resolution, downsample, border, std::max(size_x, 1));
}

FinishedMap finish_grid_by_columns(const ColumnStrip &columns, int size_x, int size_y, double resolution,
                                   int downsample, int border, uint64_t strip_cells) {
  finish::check_arguments(downsample, border);
  // Block columns per strip: as many as fit strip_cells, at least one.
  const uint64_t per_block = static_cast<uint64_t>(downsample) * static_cast<uint64_t>(std::max(size_y, 1));
  const uint64_t n = std::max<uint64_t>(1, strip_cells / per_block);
  const int strip_blocks = static_cast<int>(std::min<uint64_t>(n, static_cast<uint64_t>(std::max(size_x, 1))));
  return finish_strips(columns, size_x, size_y, resolution, downsample, border, strip_blocks);
}

}  // namespace vasco
