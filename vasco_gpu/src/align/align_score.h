// align_score.h — the score of one (rotation, translation) of the moving
// map's wall points on the reference's likelihood field: small functions over
// plain arrays, so that other searches (a GPU kernel per candidate) share
// the arithmetic the CPU search uses.
//
// A candidate is a rotation theta about the points' centroid c and a
// translation t: point p goes to R(theta) (p - c) + t, in metres from the
// reference grid's lower-left corner. The search works on whole cells at the
// matching cell h: the point's cell is floor(R(theta) (p - c) / h) plus the
// translation in cells, so that a translation moves every point by whole
// cells and the max-pooled levels bound the score exactly.
#ifndef VASCO_GPU_SRC_ALIGN_ALIGN_SCORE_H
#define VASCO_GPU_SRC_ALIGN_ALIGN_SCORE_H

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace vasco {
namespace align_detail {

// The cells of points (px, py) rotated by theta about (c_x, c_y), at cell h.
inline void rotated_cells(const double *px, const double *py, int n, double c_x, double c_y, double theta, double h,
                          int32_t *cell_x, int32_t *cell_y) {
  const double c = std::cos(theta), s = std::sin(theta);
  for (int i = 0; i < n; ++i) {
    const double dx = px[i] - c_x, dy = py[i] - c_y;
    cell_x[i] = static_cast<int32_t>(std::floor((c * dx - s * dy) / h));
    cell_y[i] = static_cast<int32_t>(std::floor((s * dx + c * dy) / h));
  }
}

// The sum of a grid's values at cells (cell_x[i] + tx, cell_y[i] + ty), 0
// where the grid stores none; the grid is x-major, size_x by size_y, its
// cell (0, 0) at map cell (-offset, -offset). A float sum in index order: a
// grid whose every value is at least another's gives a sum at least the
// other's (rounding is monotone), so the pooled levels' sums stay bounds.
inline float sum_at_cells(const float *value, int offset, int size_x, int size_y, const int32_t *cell_x,
                          const int32_t *cell_y, int n, int tx, int ty) {
  const int ox = tx + offset, oy = ty + offset;
  float sum = 0;
  for (int i = 0; i < n; ++i) {
    const auto x = static_cast<uint32_t>(cell_x[i] + ox), y = static_cast<uint32_t>(cell_y[i] + oy);
    if (x < static_cast<uint32_t>(size_x) && y < static_cast<uint32_t>(size_y))
      sum += value[static_cast<size_t>(x) * static_cast<size_t>(size_y) + y];
  }
  return sum;
}

// The field (x-major, cell h, 0 outside) interpolated bilinearly between
// cell centres at (wx, wy) metres from its lower-left corner.
inline double bilinear_at(const float *value, int size_x, int size_y, double h, double wx, double wy) {
  const double u = wx / h - 0.5, v = wy / h - 0.5;
  const double fu = std::floor(u), fv = std::floor(v);
  if (!(fu >= -1 && fv >= -1 && fu < size_x && fv < size_y)) return 0.0;
  const int x0 = static_cast<int>(fu), y0 = static_cast<int>(fv);
  const double ax = u - fu, ay = v - fv;
  auto at = [&](int x, int y) -> double {
    return x < 0 || y < 0 || x >= size_x || y >= size_y ? 0.0 : value[static_cast<size_t>(x) * size_y + y];
  };
  return (1 - ax) * ((1 - ay) * at(x0, y0) + ay * at(x0, y0 + 1)) +
         ax * ((1 - ay) * at(x0 + 1, y0) + ay * at(x0 + 1, y0 + 1));
}

// The continuous score's sum: every point at R(theta) (p - c) + (tx, ty) on
// the interpolated field; what the refinement climbs.
inline double sum_bilinear(const float *value, int size_x, int size_y, double h, const double *px, const double *py,
                           int n, double c_x, double c_y, double theta, double tx, double ty) {
  const double c = std::cos(theta), s = std::sin(theta);
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double dx = px[i] - c_x, dy = py[i] - c_y;
    sum += bilinear_at(value, size_x, size_y, h, c * dx - s * dy + tx, s * dx + c * dy + ty);
  }
  return sum;
}

}  // namespace align_detail
}  // namespace vasco

#endif  // VASCO_GPU_SRC_ALIGN_ALIGN_SCORE_H
