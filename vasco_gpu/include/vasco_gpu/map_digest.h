// map_digest.h — MOVED to carmen_compat/map_digest.h (namespace carmen): the
// GRIDMAP digest needs only the map, so it sits beside the maps. This header
// keeps the old name and vasco::gridmap_payload_sha256 compiling; new code
// includes carmen_compat/map_digest.h.
#ifndef VASCO_GPU_MAP_DIGEST_H
#define VASCO_GPU_MAP_DIGEST_H

#include "carmen_compat/map_digest.h"

namespace vasco {

using carmen::gridmap_payload_sha256;

}  // namespace vasco

#endif  // VASCO_GPU_MAP_DIGEST_H
