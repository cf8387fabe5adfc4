// A map as the int8 data of a nav_msgs/OccupancyGrid: what map_server
// publishes for the image write_map_server_pair writes, without the image.
#pragma once

#include <cstdint>
#include <vector>

#include "carmen_compat/image_io.h"
#include "carmen_compat/map_file.h"
#include "carmen_compat/occupancy_value.h"

namespace carmen {

// The cells of `map` as OccupancyGrid data: row-major from the lower-left
// cell (row 0 is y 0, x along a row; CARMEN's cells are x-major, so this is
// the transpose), -1 unknown, else 0..100. `o.mode`:
//  Trinary: 100 for an off-limits cell or p > occupied_thresh, 0 for
//           p < free_thresh, else -1: what map_server makes of a trinary
//           picture (the thresholds compared as doubles, as map_server does).
//  Raw:     round(100 p) (halves up), off-limits 100: the raw picture's level
//           read as int8, unknown 255 being -1.
// Scale (map_server's reading of a scale picture, a grey level's
// occupancy) and negate have no use here: std::invalid_argument, as for an
// empty map or cells that disagree with the size. The thresholds are taken as
// given (the caller validates them; no grey level is needed between them).
std::vector<int8_t> occupancy_grid_data(const GridMap &map, const MapServerOptions &o);
// The same into out[size_x * size_y].
void occupancy_grid_data(const GridMap &map, const MapServerOptions &o, int8_t *out);

// `o` as the per-cell rule of occupancy_value.h (std::invalid_argument for
// scale or negate, as above): what a GPU converting a map needs.
OccupancyValues occupancy_values(const MapServerOptions &o);
// The same conversion of size_x * size_y cells, x-major
// (cells[x * size_y + y]), by that rule, into out[size_x * size_y].
void occupancy_grid_data(const float *cells, int size_x, int size_y, const OccupancyValues &values, int8_t *out);
// `map` by that rule (its size checked as above), into out[size_x * size_y].
void occupancy_grid_data(const GridMap &map, const OccupancyValues &values, int8_t *out);

}  // namespace carmen
