// The fixed layouts of a map file's chunk payloads (CREATOR, OFFSET, PLACES,
// LASERSCANS), parsed from bytes held in memory by the map reader
// (map_file_reader.h). Every count a payload claims is checked against the
// bytes it holds before anything is allocated for it.
#ifndef CARMEN_COMPAT_MAP_FILE_PAYLOADS_H
#define CARMEN_COMPAT_MAP_FILE_PAYLOADS_H

#include <string>
#include <vector>

#include "carmen_compat/map_file.h"

namespace carmen::map_read {

// Why a payload does not parse, in words that follow the chunk's name
// ("has 12 payload bytes; ..."): the reader adds the file and the chunk.
struct ParseError {
  std::string what;
};

// payload = the bytes after the chunk's description and name.
CreatorInfo parse_creator(const std::vector<unsigned char> &payload);
GlobalOffset parse_offset(const std::vector<unsigned char> &payload);
PlaceList parse_places(const std::vector<unsigned char> &payload);
LaserScanList parse_laserscans(const std::vector<unsigned char> &payload);

}  // namespace carmen::map_read

#endif  // CARMEN_COMPAT_MAP_FILE_PAYLOADS_H
