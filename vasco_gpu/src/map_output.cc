#include "vasco_gpu/map_output.h"

#include <utility>

namespace vasco {

carmen::GlobalOffset world_origin(const FinishedMap &map, const GridGeometry &geo) {
  return carmen::GlobalOffset{geo.world_x(static_cast<double>(map.min_x) * map.downsample),
                              geo.world_y(static_cast<double>(map.min_y) * map.downsample), 0.0};
}

carmen::MapToWrite map_to_write(FinishedMap map, const GridGeometry &geo) {
  carmen::MapToWrite out;
  out.origin = world_origin(map, geo);
  out.grid.size_x = map.size_x;
  out.grid.size_y = map.size_y;
  out.grid.resolution = map.resolution;
  out.grid.cells = std::move(map.cells);
  return out;
}

}  // namespace vasco
