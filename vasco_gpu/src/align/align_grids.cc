#include "align_grids.h"

#include <algorithm>
#include <cmath>

namespace vasco {
namespace align_detail {
namespace {

// Cells of `n` cells of `from` metres that fit `to`-metre cells: the output
// covers the input whole.
int cells_covering(int n, double from, double to) {
  return std::max(1, static_cast<int>(std::ceil(n * from / to - 1e-9)));
}

// A probability as the grids keep it: NaN and negatives unknown (-1), above
// 1 clamped.
float clean(float v) { return v >= 0 ? std::min(v, 1.0f) : -1.0f; }

}  // namespace

MatchGrid resample(const AlignMap &map, double h) {
  MatchGrid g;
  g.resolution = h;
  g.origin_x = map.origin_x;
  g.origin_y = map.origin_y;
  if (map.size_x <= 0 || map.size_y <= 0) return g;
  const double r = map.resolution;
  g.size_x = cells_covering(map.size_x, r, h);
  g.size_y = cells_covering(map.size_y, r, h);
  g.cells.assign(static_cast<size_t>(g.size_x) * g.size_y, -1.0f);
  if (r < h) {
    // Max-pool: unknown (-1) loses to any known probability.
    for (int x = 0; x < map.size_x; ++x) {
      const int ox = std::min(g.size_x - 1, static_cast<int>((x + 0.5) * r / h));
      for (int y = 0; y < map.size_y; ++y) {
        const int oy = std::min(g.size_y - 1, static_cast<int>((y + 0.5) * r / h));
        float &out = g.cells[static_cast<size_t>(ox) * g.size_y + oy];
        out = std::max(out, clean(map.cells[static_cast<size_t>(x) * map.size_y + y]));
      }
    }
    return g;
  }
  for (int ox = 0; ox < g.size_x; ++ox) {
    const int x = static_cast<int>((ox + 0.5) * h / r);
    if (x >= map.size_x) continue;
    for (int oy = 0; oy < g.size_y; ++oy) {
      const int y = static_cast<int>((oy + 0.5) * h / r);
      if (y < map.size_y) g.cells[static_cast<size_t>(ox) * g.size_y + oy] = clean(map.cells[static_cast<size_t>(x) * map.size_y + y]);
    }
  }
  return g;
}

Points wall_points(const MatchGrid &grid) {
  Points p;
  for (int x = 0; x < grid.size_x; ++x)
    for (int y = 0; y < grid.size_y; ++y)
      if (grid.at(x, y) > kWallAbove) {
        p.x.push_back(grid.origin_x + (x + 0.5) * grid.resolution);
        p.y.push_back(grid.origin_y + (y + 0.5) * grid.resolution);
      }
  return p;
}

Field likelihood_field(const MatchGrid &reference) {
  Field f;
  f.size_x = reference.size_x;
  f.size_y = reference.size_y;
  const size_t n = reference.cells.size();
  f.value.assign(n, 0.0f);
  f.known.assign(n, 0);
  for (size_t i = 0; i < n; ++i) {
    const float p = reference.cells[i];
    f.known[i] = p >= 0;
    if (p >= 0 && p < kFreeBelow) f.value[i] = -kFreePenalty;
  }
  // Each wall spreads its likelihood over the disc of radius kReach; the
  // largest wins, so a free cell beside a wall is no penalty.
  float near[2 * kReach + 1][2 * kReach + 1];
  for (int dx = -kReach; dx <= kReach; ++dx)
    for (int dy = -kReach; dy <= kReach; ++dy) {
      const int d2 = dx * dx + dy * dy;
      near[dx + kReach][dy + kReach] = d2 <= kReach * kReach ? std::exp(-0.5f * d2) : -1.0f;
    }
  for (int x = 0; x < f.size_x; ++x)
    for (int y = 0; y < f.size_y; ++y) {
      if (!(reference.at(x, y) > kWallAbove)) continue;
      for (int dx = -kReach; dx <= kReach; ++dx) {
        const int nx = x + dx;
        if (nx < 0 || nx >= f.size_x) continue;
        for (int dy = -kReach; dy <= kReach; ++dy) {
          const int ny = y + dy;
          if (ny < 0 || ny >= f.size_y) continue;
          float &v = f.value[static_cast<size_t>(nx) * f.size_y + ny];
          v = std::max(v, near[dx + kReach][dy + kReach]);
        }
      }
    }
  return f;
}

namespace {

// Level `prev` at (x, y) in map cells, 0 outside what it stores.
float pooled_at(const PooledGrid &prev, int x, int y) {
  const int sx = x + prev.offset, sy = y + prev.offset;
  if (sx < 0 || sy < 0 || sx >= prev.size_x || sy >= prev.size_y) return 0.0f;
  return prev.value[static_cast<size_t>(sx) * prev.size_y + sy];
}

// The next level from `prev`: a window of 2^d is four windows of 2^(d-1).
PooledGrid next_level(const PooledGrid &prev, int map_x, int map_y) {
  PooledGrid g;
  const int half = prev.offset + 1;
  g.offset = 2 * half - 1;
  g.size_x = map_x + g.offset;
  g.size_y = map_y + g.offset;
  g.value.resize(static_cast<size_t>(g.size_x) * g.size_y);
  for (int sx = 0; sx < g.size_x; ++sx) {
    const int x = sx - g.offset;
    for (int sy = 0; sy < g.size_y; ++sy) {
      const int y = sy - g.offset;
      g.value[static_cast<size_t>(sx) * g.size_y + sy] =
          std::max(std::max(pooled_at(prev, x, y), pooled_at(prev, x + half, y)),
                   std::max(pooled_at(prev, x, y + half), pooled_at(prev, x + half, y + half)));
    }
  }
  return g;
}

}  // namespace

std::vector<PooledGrid> pool_levels(const Field &field, int levels) {
  std::vector<PooledGrid> out;
  out.reserve(static_cast<size_t>(levels));
  PooledGrid base;
  base.size_x = field.size_x;
  base.size_y = field.size_y;
  base.value = field.value;
  out.push_back(std::move(base));
  for (int d = 1; d < levels; ++d) out.push_back(next_level(out.back(), field.size_x, field.size_y));
  return out;
}

}  // namespace align_detail
}  // namespace vasco
