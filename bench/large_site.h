// large_site.h — a synthetic large-site log for mapping_bench --large: a
// robot driving once around a square loop of corridor (walls on both sides)
// that fills a site of side × side metres, starting in a corner, its 180°
// laser (361 beams, π/360 apart, as CARMEN's 361-beam FLASER) ray-cast
// against the walls. A beam that meets no wall within the laser's 50 m is
// out of range (50 m: CARMEN skips it). Deterministic: no randomness, the
// same scans on every run and machine (up to libm's cos and sin).
//
// Because the PROTOCOL frame is centred on the first pose, a robot starting
// in a corner needs a grid twice the site in each axis: a 600 m site at
// vasco's 2.5 cm is 48,486 cells a side, 2.35e9 cells (past 2^31).
#ifndef VASCO_BENCH_LARGE_SITE_H
#define VASCO_BENCH_LARGE_SITE_H

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "vasco_gpu/scan_batch.h"

namespace bench {

struct LargeSite {
  double side = 600.0;      // m: the site is [0, side]^2
  double corridor = 4.0;    // m: the corridor's width (outer wall to inner wall)
  size_t scans = 3000;      // spread evenly over one lap
  int beams = 361;          // over 180°, pi / (beams - 1) apart
  double laser_max = 50.0;  // m: a beam meeting no wall this near reads 50 (out of range)
};

// An axis-aligned wall from (x0, y0) to (x1, y1).
struct Wall {
  double x0, y0, x1, y1;
};

// The walls of the loop: the site's outer square and the inner square the
// corridor runs around.
inline std::vector<Wall> large_site_walls(const LargeSite &site) {
  const double a = 0, b = site.side, c = site.corridor, d = site.side - site.corridor;
  return {{a, a, b, a}, {b, a, b, b}, {b, b, a, b}, {a, b, a, a},   // outer
          {c, c, d, c}, {d, c, d, d}, {d, d, c, d}, {c, d, c, c}};  // inner
}

// The distance from (px, py) along (dx, dy) (a unit vector) to the nearest
// wall, or `none` when it meets none.
inline double cast_ray(const std::vector<Wall> &walls, double px, double py, double dx, double dy, double none) {
  double best = none;
  for (const Wall &w : walls) {
    if (w.y0 == w.y1) {  // horizontal
      if (dy == 0) continue;
      const double t = (w.y0 - py) / dy;
      const double x = px + t * dx;
      if (t > 0 && t < best && x >= std::min(w.x0, w.x1) && x <= std::max(w.x0, w.x1)) best = t;
    } else {  // vertical
      if (dx == 0) continue;
      const double t = (w.x0 - px) / dx;
      const double y = py + t * dy;
      if (t > 0 && t < best && y >= std::min(w.y0, w.y1) && y <= std::max(w.y0, w.y1)) best = t;
    }
  }
  return best;
}

// The scans of one lap, counter-clockwise from the corner (corridor / 2,
// corridor / 2), heading along the corridor: laser poses in metres.
inline vasco::ScanBatch large_site_scans(const LargeSite &site) {
  const std::vector<Wall> walls = large_site_walls(site);
  const double c = site.corridor / 2, leg = site.side - site.corridor, lap = 4 * leg;
  const double step = M_PI / (site.beams - 1), first = -M_PI / 2;
  vasco::ScanBatch batch;
  std::vector<float> ranges(static_cast<size_t>(site.beams));
  for (size_t s = 0; s < site.scans; ++s) {
    const double u = lap * static_cast<double>(s) / static_cast<double>(site.scans);
    const int k = std::min(3, static_cast<int>(u / leg));  // which leg
    const double along = u - k * leg;
    double x = c, y = c;
    const double theta = k * M_PI / 2;  // 0, pi/2, pi, 3pi/2
    switch (k) {
      case 0: x = c + along; break;
      case 1: x = c + leg, y = c + along; break;
      case 2: x = c + leg - along, y = c + leg; break;
      default: y = c + leg - along; break;
    }
    for (int b = 0; b < site.beams; ++b) {
      const double a = theta + first + b * step;
      const double r = cast_ray(walls, x, y, std::cos(a), std::sin(a), site.laser_max);
      ranges[static_cast<size_t>(b)] = static_cast<float>(std::min(r, site.laser_max));
    }
    batch.add_scan(x, y, theta, first, step, ranges.data(), site.beams, static_cast<long>(s + 1));
  }
  return batch;
}

}  // namespace bench

#endif  // VASCO_BENCH_LARGE_SITE_H
