// map_digest.h — the SHA-256 of a GRIDMAP payload, the fingerprint the
// CARMEN golden maps are published with: int32 size_x, int32 size_y, float32
// resolution, then size_x * size_y float32 cells in x-major order, all
// little-endian. Comments, creator time and gzip bytes are not part of it, so
// two maps with equal digests have bit-identical grids.
#ifndef CARMEN_COMPAT_MAP_DIGEST_H
#define CARMEN_COMPAT_MAP_DIGEST_H

#include <string>
#include <vector>

namespace carmen {

// Lower-case hex SHA-256 of the GRIDMAP payload of a size_x x size_y grid
// (cells x-major, cells.size() == size_x * size_y; throws
// std::invalid_argument otherwise).
std::string gridmap_payload_sha256(int size_x, int size_y, double resolution,
                                   const std::vector<float> &cells);

}  // namespace carmen

#endif  // CARMEN_COMPAT_MAP_DIGEST_H
