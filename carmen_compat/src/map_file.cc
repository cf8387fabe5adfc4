// CARMEN map files: what the reader and the writer share (chunk names, cell
// values, GridMap). Reading is map_file_reader.h (map_file_read.cc, its
// chunks' data map_file_read_chunks.cc, map_file_payloads.cc), writing
// map_file_write.cc.
#include "carmen_compat/map_file.h"

#include <stdexcept>
#include <string>
#include <type_traits>

namespace carmen {

std::string chunk_description(int type) {
  switch (type & ~kNamedChunkFlag) {
    case kGridmapChunk: return "GRIDMAP   ";
    case kOfflimitsChunk: return "OFFLIMITS ";
    case kHmapChunk: return "HMAP      ";
    case kPlacesChunk: return "PLACES    ";
    case kExpectedChunk: return "EXPECTED  ";
    case kLaserscansChunk: return "LASERSCANS";
    case kCreatorChunk: return "CREATOR   ";
    case kGlobalOffsetChunk: return "OFFSET    ";
    default: return "UNKNOWN   ";
  }
}

std::string chunk_type_name(int type) {
  const int base = type & ~kNamedChunkFlag;
  switch (base) {
    case kOldCreatorChunk: return "old-style CREATOR";
    case kGridmapChunk: return "GRIDMAP";
    case kOfflimitsChunk: return "OFFLIMITS";
    case kHmapChunk: return "HMAP";
    case kPlacesChunk: return "PLACES";
    case kExpectedChunk: return "EXPECTED";
    case kLaserscansChunk: return "LASERSCANS";
    case kCreatorChunk: return "CREATOR";
    case kGlobalOffsetChunk: return "OFFSET";
    default: return "type-" + std::to_string(base);
  }
}

bool valid_cell_value(float v) {
  return v == kUnknownCell || (v >= 0.0f && v <= 1.0f) || (v >= 2.0f && v <= 3.0f);
}

float GridMap::at(int x, int y) const {
  if (!contains(x, y)) {
    throw std::out_of_range("cell (" + std::to_string(x) + ", " + std::to_string(y) + ") outside a " +
                            std::to_string(size_x) + " x " + std::to_string(size_y) + " map");
  }
  return cells.at(size_t(x) * size_t(size_y) + size_t(y));
}

float &GridMap::at(int x, int y) {
  if (!contains(x, y)) {
    throw std::out_of_range("cell (" + std::to_string(x) + ", " + std::to_string(y) + ") outside a " +
                            std::to_string(size_x) + " x " + std::to_string(size_y) + " map");
  }
  return cells.at(size_t(x) * size_t(size_y) + size_t(y));
}

GridMap GridMap::filled(int size_x, int size_y, double resolution, float value) {
  if (size_x < 0 || size_y < 0) throw std::invalid_argument("negative map size");
  GridMap g;
  g.size_x = size_x;
  g.size_y = size_y;
  g.resolution = resolution;
  g.cells.assign(size_t(size_x) * size_t(size_y), value);
  return g;
}

int NamedChunk::type() const {
  return std::visit(
      [](const auto &p) -> int {
        using T = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<T, GridMap>)
          return kGridmapChunk;
        else if constexpr (std::is_same_v<T, OffLimits>)
          return kOfflimitsChunk;
        else if constexpr (std::is_same_v<T, PlaceList>)
          return kPlacesChunk;
        else if constexpr (std::is_same_v<T, LaserScanList>)
          return kLaserscansChunk;
        else if constexpr (std::is_same_v<T, CreatorInfo>)
          return kCreatorChunk;
        else
          return kGlobalOffsetChunk;
      },
      payload);
}


}  // namespace carmen
