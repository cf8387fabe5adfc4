#include "vasco_gpu/grid.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

void PoseExtent::add(const ScanBatch &batch, size_t first, size_t last) {
  for (size_t s = first; s < last; ++s) {
    if (scans++ == 0) {
      x0 = batch.x[s];
      y0 = batch.y[s];
      theta0 = batch.theta[s];
    }
    const double dx = std::fabs(batch.x[s] - x0), dy = std::fabs(batch.y[s] - y0);
    if (dx > mx) mx = dx, far_x = s;
    if (dy > my) my = dy, far_y = s;
  }
}

GridGeometry size_grid(const ScanBatch &batch, const MapperParams &params) {
  PoseExtent e;
  e.add(batch, 0, batch.num_scans());
  return size_grid(e, batch, params);
}

GridGeometry size_grid(const PoseExtent &e, const ScanBatch &batch, const MapperParams &params) {
  if (e.scans == 0) throw std::runtime_error("no laser scans to map");
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
    throw std::runtime_error(msg.str());
  }
  g.size_x = static_cast<int>(sx);
  g.size_y = static_cast<int>(sy);
  return g;
}

FinishedMap finish_grid(const float *cells, int size_x, int size_y, double resolution,
                        int downsample, int border) {
  if (downsample < 1) throw std::invalid_argument("downsample must be at least 1");
  if (border < 0) throw std::invalid_argument("border must not be negative");
  const int ds = downsample;
  const int nx = size_x / ds, ny = size_y / ds;
  std::vector<float> blocks(static_cast<size_t>(nx) * ny);
  int min_x = nx - border - 1, max_x = border;
  int min_y = ny - border - 1, max_y = border;
  for (int bx = 0; bx < nx; ++bx) {
    for (int by = 0; by < ny; ++by) {
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
      float v = -1.0f;
      if (count > 0) {
        v = static_cast<float>(sum / static_cast<double>(count));
        if (bx < min_x) min_x = bx;
        if (bx > max_x) max_x = bx;
        if (by < min_y) min_y = by;
        if (by > max_y) max_y = by;
      }
      blocks[static_cast<size_t>(bx) * ny + by] = v;
    }
  }
  min_x -= border;
  if (min_x < 0) min_x = 0;
  max_x += border;
  if (max_x > nx - 1) max_x = nx - 1;
  min_y -= border;
  if (min_y < 0) min_y = 0;
  max_y += border;
  if (max_y > ny - 1) max_y = ny - 1;

  FinishedMap m;
  m.downsample = ds;
  m.resolution = resolution * ds;
  m.min_x = min_x;
  m.min_y = min_y;
  // CARMEN's new size is max - min, without +1: the last row and column go.
  m.size_x = max_x - min_x > 0 ? max_x - min_x : 0;
  m.size_y = max_y - min_y > 0 ? max_y - min_y : 0;
  m.cells.resize(static_cast<size_t>(m.size_x) * m.size_y);
  for (int x = 0; x < m.size_x; ++x)
    for (int y = 0; y < m.size_y; ++y)
      m.cells[static_cast<size_t>(x) * m.size_y + y] =
          blocks[static_cast<size_t>(x + min_x) * ny + (y + min_y)];
  return m;
}

}  // namespace vasco
