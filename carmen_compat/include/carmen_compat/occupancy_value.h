// One cell of a map as nav_msgs/OccupancyGrid data (occupancy_grid.h), written
// once for the host's conversion (occupancy_grid.cc) and the GPU's
// (vasco_gpu's finish_kernels.cu, which converts the finished map on the
// device and sends the bytes the node publishes): the same byte wherever it
// runs. Pure functions of their arguments, no library call.
#ifndef CARMEN_COMPAT_OCCUPANCY_VALUE_H
#define CARMEN_COMPAT_OCCUPANCY_VALUE_H

#include <cstdint>

#include "carmen_compat/host_device.h"

namespace carmen {

// What the values are, decided once for a map (occupancy_values() in
// occupancy_grid.h makes it from map_server's options).
//  raw false (trinary): 100 for v > occupied, 0 for v < free, else -1;
//  raw true: round(100 p) (halves up), 1 and above 100.
// Unknown cells (NaN or negative: CARMEN's -1) are -1 in both.
struct OccupancyValues {
  bool raw = false;
  float occupied = 0.0f;  // the largest float not above occupied_thresh
  float free = 0.0f;      // the smallest float not below free_thresh
};

// A cell's state as the images read it (image_io.h's is_unknown is this).
VG_HD bool unknown_cell(float v) { return !(v >= 0.0f); }

// raw: round(100 p), halves up, as floor(100 p + 0.5): exact for every float
// p in [0, 1]. 100 p needs at most 24 + 7 significant bits, so it is exact in
// double and a fused multiply-add gives the same sum; the sum then rounds
// only where 100 p + 0.5 has bits below 2^-46, that is for p below about
// 2^-23, where it stays under 1 either way. 1 and above (off-limits too)
// 100. No NaN is converted.
VG_HD int8_t raw_occupancy_value(float v) {
  const double p = unknown_cell(v) ? 0.0 : (double(v) < 1.0 ? double(v) : 1.0);
  const int8_t level = static_cast<int8_t>(100.0 * p + 0.5);
  return unknown_cell(v) ? int8_t(-1) : level;
}

// trinary: map_server's double comparisons (p > occupied_thresh, p <
// free_thresh) made on the float cells by the float bounds that decide them
// alike. An off-limits cell (2 and above) is above any occupied_thresh (at
// most 1), a cell between 1 and 2 too: both 100, as is_offlimits and clamp01
// have it in the pictures.
VG_HD int8_t trinary_occupancy_value(float occupied, float free, float v) {
  const int8_t known = v > occupied ? int8_t(100) : v < free ? int8_t(0) : int8_t(-1);
  return unknown_cell(v) ? int8_t(-1) : known;
}

VG_HD int8_t occupancy_value(const OccupancyValues &o, float v) {
  return o.raw ? raw_occupancy_value(v) : trinary_occupancy_value(o.occupied, o.free, v);
}

}  // namespace carmen

#endif  // CARMEN_COMPAT_OCCUPANCY_VALUE_H
