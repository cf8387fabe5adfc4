// mapconvert_info.h — what mapconvert --info prints about a map.
#ifndef VASCO_GPU_APP_MAPCONVERT_INFO_H
#define VASCO_GPU_APP_MAPCONVERT_INFO_H

#include <string>

#include "carmen_compat/map_file.h"

namespace mapconvert {

// Prints what `m`, read from `path`, holds: its chunks, creator, offset,
// places, off-limits, scans and its grid's size, resolution, unknown
// fraction and value range. `format`: the format table's words for a file
// that is not a CARMEN map (no comments, no chunks to list), else nullptr.
void print_info(const std::string &path, const carmen::MapFile &m, const char *format);

}  // namespace mapconvert

#endif  // VASCO_GPU_APP_MAPCONVERT_INFO_H
