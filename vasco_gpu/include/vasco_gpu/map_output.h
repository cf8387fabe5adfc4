// map_output.h — a finished map as a map to write (carmen_compat/map_format.h):
// its cells and the world pose of its cell (0, 0), computed here once for
// log2map and the Python binding.
#ifndef VASCO_GPU_MAP_OUTPUT_H
#define VASCO_GPU_MAP_OUTPUT_H

#include "carmen_compat/map_format.h"
#include "vasco_gpu/grid.h"

namespace vasco {

// The world pose of the lower-left corner of `map`'s cell (0, 0) in the grid
// frame `geo` it was finished from: finish crops at (min_x, min_y) in
// downsampled cells, i.e. at fine cell (min_x, min_y) * downsample. theta is
// 0: the frame's theta_offset is the first scan's heading, and the grid axes
// are the world axes.
carmen::GlobalOffset world_origin(const FinishedMap &map, const GridGeometry &geo);

// `map` with its origin, ready for carmen::write_map (the creator fields are
// left for the caller to fill in).
carmen::MapToWrite map_to_write(FinishedMap map, const GridGeometry &geo);

}  // namespace vasco

#endif  // VASCO_GPU_MAP_OUTPUT_H
