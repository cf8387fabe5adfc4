#include "vasco_gpu/grid.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>

#include "vasco_gpu/error.h"
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

namespace {

// The downsampled blocks and CARMEN's crop bounds (64-bit: min starts at
// n - border - 1 and max at border, both widened by known blocks).
struct Blocks {
  int nx = 0, ny = 0;
  std::vector<float> cells;  // x-major, -1 unknown
  int64_t min_x = 0, max_x = 0, min_y = 0, max_y = 0;
};

// The mean of block (bx, by)'s known cells, summed in double; false when
// none is known.
bool block_mean(const float *cells, int size_y, int bx, int by, int ds, float *mean) {
  double sum = 0;
  int count = 0;
  for (int i = bx * ds; i < (bx + 1) * ds; ++i) {
    const float *col = cells + static_cast<size_t>(i) * size_y;
    for (int j = by * ds; j < (by + 1) * ds; ++j) {
      if (col[j] != -1.0f) {
        sum += col[j];
        ++count;
      }
    }
  }
  *mean = count > 0 ? static_cast<float>(sum / static_cast<double>(count)) : -1.0f;
  return count > 0;
}

Blocks downsample_blocks(const float *cells, int size_x, int size_y, int ds, int64_t border) {
  Blocks b;
  b.nx = size_x / ds;
  b.ny = size_y / ds;
  b.cells.resize(static_cast<size_t>(b.nx) * b.ny);
  b.min_x = b.nx - border - 1, b.max_x = border;
  b.min_y = b.ny - border - 1, b.max_y = border;
  for (int bx = 0; bx < b.nx; ++bx) {
    for (int by = 0; by < b.ny; ++by) {
      float v;
      if (block_mean(cells, size_y, bx, by, ds, &v)) {
        b.min_x = std::min<int64_t>(b.min_x, bx), b.max_x = std::max<int64_t>(b.max_x, bx);
        b.min_y = std::min<int64_t>(b.min_y, by), b.max_y = std::max<int64_t>(b.max_y, by);
      }
      b.cells[static_cast<size_t>(bx) * b.ny + by] = v;
    }
  }
  return b;
}

}  // namespace

FinishedMap finish_grid(const float *cells, int size_x, int size_y, double resolution,
                        int downsample, int border) {
  if (downsample < 1) throw Error(ErrorCode::Usage, "downsample must be at least 1");
  if (border < 0) throw Error(ErrorCode::Usage, "border must not be negative");
  const Blocks b = downsample_blocks(cells, size_x, size_y, downsample, border);
  const int64_t min_x = std::max<int64_t>(b.min_x - border, 0), max_x = std::min<int64_t>(b.max_x + border, b.nx - 1);
  const int64_t min_y = std::max<int64_t>(b.min_y - border, 0), max_y = std::min<int64_t>(b.max_y + border, b.ny - 1);
  FinishedMap m;
  m.downsample = downsample;
  m.resolution = resolution * downsample;
  // Inside [0, n - 1] after the clamps: they fit an int.
  m.min_x = static_cast<int>(std::min<int64_t>(min_x, b.nx));
  m.min_y = static_cast<int>(std::min<int64_t>(min_y, b.ny));
  // CARMEN's new size is max - min, without +1: the last row and column go.
  m.size_x = max_x - min_x > 0 ? static_cast<int>(max_x - min_x) : 0;
  m.size_y = max_y - min_y > 0 ? static_cast<int>(max_y - min_y) : 0;
  m.cells.resize(static_cast<size_t>(m.size_x) * m.size_y);
  for (int x = 0; x < m.size_x; ++x)
    for (int y = 0; y < m.size_y; ++y)
      m.cells[static_cast<size_t>(x) * m.size_y + y] = b.cells[static_cast<size_t>(x + m.min_x) * b.ny + (y + m.min_y)];
  return m;
}

}  // namespace vasco
