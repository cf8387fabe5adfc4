// nav_msgs/OccupancyGrid data of a map (occupancy_grid.h).
#include "carmen_compat/occupancy_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace carmen {
namespace {

// out[y * size_x + x] = value(cells[x * size_y + y]), a tile at a time: the tile's values in
// the cells' order (a loop of selects the compiler vectorises) into a buffer on the stack,
// then transposed into the rows (whole cache lines read and written). No heap memory: a map's
// worth of scratch, allocated for each map the node publishes, cost page faults every time.
template <typename ValueFn>
void transposed(const GridMap &map, ValueFn value, int8_t *out) {
  constexpr size_t kTile = 64;
  const size_t w = size_t(map.size_x), h = size_t(map.size_y);
  const float *cells = map.cells.data();
  int8_t tile[kTile][kTile];  // [x - x0][y - y0]
  for (size_t x0 = 0; x0 < w; x0 += kTile) {
    const size_t x1 = std::min(w, x0 + kTile);
    for (size_t y0 = 0; y0 < h; y0 += kTile) {
      const size_t y1 = std::min(h, y0 + kTile);
      for (size_t x = x0; x < x1; ++x) {
        const float *column = cells + x * h;
        for (size_t y = y0; y < y1; ++y) tile[x - x0][y - y0] = value(column[y]);
      }
      for (size_t y = y0; y < y1; ++y) {
        int8_t *row = out + y * w;
        for (size_t x = x0; x < x1; ++x) row[x] = tile[x - x0][y - y0];
      }
    }
  }
}

// The float f with f > v exactly when double(f) > t: the largest float not above t.
float largest_float_not_above(double t) {
  float f = static_cast<float>(t);
  if (double(f) > t) f = std::nextafter(f, -INFINITY);
  return f;
}

// The float f with v < f exactly when double(v) < t: the smallest float not below t.
float smallest_float_not_below(double t) {
  float f = static_cast<float>(t);
  if (double(f) < t) f = std::nextafter(f, INFINITY);
  return f;
}

}  // namespace

void occupancy_grid_data(const GridMap &map, const MapServerOptions &o, int8_t *out) {
  check_map_size(map, "occupancy grid data");
  if (o.negate) throw std::invalid_argument("occupancy grid data: negate has no meaning here");
  switch (o.mode) {
    case PgmMode::Trinary: {
      // map_server's double comparisons (p > occupied_thresh, p < free_thresh) made on the
      // float cells by the float bounds that decide them alike. An off-limits cell (2 and
      // above) is above any occupied_thresh (at most 1), a cell between 1 and 2 too: both 100,
      // as is_offlimits and clamp01 have it in the pictures.
      const float occupied = largest_float_not_above(o.occupied_thresh);
      const float free = smallest_float_not_below(o.free_thresh);
      transposed(map, [occupied, free](float v) -> int8_t {
        const int8_t known = v > occupied ? int8_t(100) : v < free ? int8_t(0) : int8_t(-1);
        return is_unknown(v) ? int8_t(-1) : known;
      }, out);
      return;
    }
    case PgmMode::Raw:
      transposed(map, [](float v) -> int8_t {
        // round(100 p), halves up, as floor(100 p + 0.5): exact for every float p in [0, 1]
        // (100 p is then a multiple of 2^-22 below 2^7, so adding 0.5 rounds nothing); 1 and
        // above (off-limits too) 100
        const double p = is_unknown(v) ? 0.0 : std::min(double(v), 1.0);  // no NaN converted
        const int8_t level = static_cast<int8_t>(100.0 * p + 0.5);
        return is_unknown(v) ? int8_t(-1) : level;
      }, out);
      return;
    case PgmMode::Scale:
      break;
  }
  throw std::invalid_argument("occupancy grid data: mode scale (a grey level's occupancy) has no meaning here");
}

std::vector<int8_t> occupancy_grid_data(const GridMap &map, const MapServerOptions &o) {
  std::vector<int8_t> out(map.cells.size());  // the size is checked before anything is written
  occupancy_grid_data(map, o, out.data());
  return out;
}

}  // namespace carmen
