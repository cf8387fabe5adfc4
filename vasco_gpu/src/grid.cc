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
  if (batch.num_scans() > 0) oracle::scan_start(frame, batch.x[0], batch.y[0], batch.theta[0]);
  return frame;
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
  if (!(sx * sy <= static_cast<double>(kMaxGridCells)) || !(sx < 2147483647.0) ||
      !(sy < 2147483647.0)) {
    auto line = [&](size_t s) { return s < batch.line.size() ? batch.line[s] : static_cast<long>(s); };
    std::ostringstream msg;
    msg << "the poses span " << 2 * e.mx << " m x " << 2 * e.my << " m (from the scan at line "
        << line(0) << " to line " << line(e.far_x) << " in x and line " << line(e.far_y)
        << " in y): a grid of " << sx << " x " << sy << " cells at " << params.resolution
        << " m is too large (limit " << kMaxGridCells
        << " cells); check the poses or raise vasco_resolution";
    throw Error(ErrorCode::TooLarge, msg.str());
  }
  g.size_x = static_cast<int>(sx);
  g.size_y = static_cast<int>(sy);
  return g;
}

// CARMEN's finish (finish_math.h, the same functions the GPU's finish
// kernels run): block means, the known box, the crop and its cells.
FinishedMap finish_grid(const float *cells, int size_x, int size_y, double resolution,
                        int downsample, int border) {
  finish::check_arguments(downsample, border);
  const finish::Blocks blocks = finish::blocks_of(size_x, size_y, downsample);
  std::vector<float> means(static_cast<size_t>(blocks.count()));
  finish::KnownBox known;
  const auto cell_at = [cells](int64_t c) { return cells[c]; };
  for (int bx = 0; bx < blocks.nx; ++bx) {
    for (int by = 0; by < blocks.ny; ++by) {
      const finish::BlockMean m = finish::block_mean(cell_at, size_y, downsample, bx, by);
      if (m.known) finish::widen(known, bx, by);
      means[static_cast<size_t>(bx) * blocks.ny + by] = m.value;
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

}  // namespace vasco
