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
void transposed(const float *cells, size_t w, size_t h, ValueFn value, int8_t *out) {
  constexpr size_t kTile = 64;
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

OccupancyValues occupancy_values(const MapServerOptions &o) {
  if (o.negate) throw std::invalid_argument("occupancy grid data: negate has no meaning here");
  switch (o.mode) {
    case PgmMode::Trinary:
      return OccupancyValues{false, largest_float_not_above(o.occupied_thresh), smallest_float_not_below(o.free_thresh)};
    case PgmMode::Raw:
      return OccupancyValues{true, 0.0f, 0.0f};
    case PgmMode::Scale:
      break;
  }
  throw std::invalid_argument("occupancy grid data: mode scale (a grey level's occupancy) has no meaning here");
}

// One loop per rule (occupancy_value.h's two), so that each vectorises without a test per cell.
void occupancy_grid_data(const float *cells, int size_x, int size_y, const OccupancyValues &values, int8_t *out) {
  const size_t w = static_cast<size_t>(size_x), h = static_cast<size_t>(size_y);
  if (values.raw) {
    transposed(cells, w, h, [](float v) { return raw_occupancy_value(v); }, out);
  } else {
    const float occupied = values.occupied, free = values.free;
    transposed(cells, w, h, [occupied, free](float v) { return trinary_occupancy_value(occupied, free, v); }, out);
  }
}

void occupancy_grid_data(const GridMap &map, const OccupancyValues &values, int8_t *out) {
  check_map_size(map, "occupancy grid data");
  occupancy_grid_data(map.cells.data(), map.size_x, map.size_y, values, out);
}

void occupancy_grid_data(const GridMap &map, const MapServerOptions &o, int8_t *out) {
  occupancy_grid_data(map, occupancy_values(o), out);
}

std::vector<int8_t> occupancy_grid_data(const GridMap &map, const MapServerOptions &o) {
  std::vector<int8_t> out(map.cells.size());  // the size is checked before anything is written
  occupancy_grid_data(map, o, out.data());
  return out;
}

}  // namespace carmen
