// Map images: a ROS map_server / nav2 PGM + YAML pair, and PNG for people.
//
// Orientation (both formats, map_server's convention): image column c is
// cell x = c, image row r (row 0 at the top) is cell y = size_y - 1 - r, so
// +y points up in the picture.
//
// Cell values: p in [0, 1] is an occupancy probability; any negative value
// (CARMEN's -1) and NaN are unknown; values >= 2 (CARMEN's in-memory
// off-limits overlay, p + 2) are drawn as occupied.
#ifndef CARMEN_COMPAT_IMAGE_IO_H
#define CARMEN_COMPAT_IMAGE_IO_H

#include <cstdint>
#include <string>
#include <vector>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/map_file.h"

namespace carmen {

// map_server's thresholds, written to the YAML and used by Trinary.
constexpr double kOccupiedThresh = 0.65;
constexpr double kFreeThresh = 0.196;

// Grey levels (0 = black).
//  Trinary: occupied (p > 0.65) 0, free (p < 0.196) 254, otherwise — unknown
//           or in between — 205 (map_server reads 205 as unknown: (255-205)/255
//           = 0.196 is neither below free_thresh nor above occupied_thresh).
//  Scale:   round(255 * (1 - p)); unknown 205 (a PGM has no alpha channel,
//           so map_server's scale mode cannot express unknown exactly; 205 is
//           what map_server reads as occupancy 0.196, the free threshold).
//  Raw:     round(100 * p) (0..100, the occupancy value itself); unknown 255,
//           which map_server's raw mode passes on as -1 in the int8
//           OccupancyGrid; off-limits 100.
enum class PgmMode { Trinary, Scale, Raw };
constexpr uint8_t kPgmOccupied = 0;
constexpr uint8_t kPgmFree = 254;
constexpr uint8_t kPgmUnknown = 205;
constexpr uint8_t kPgmRawUnknown = 255;
constexpr uint8_t kPngUnknown = 128;  // PNG: round(255 * (1 - p)); unknown mid grey

// "trinary", "scale", "raw" (as in the YAML's mode key).
const char *pgm_mode_name(PgmMode mode);
// Parses a mode name; false if it is none of the three.
bool parse_pgm_mode(const std::string &name, PgmMode *mode);

// The grey level of one cell value.
uint8_t pgm_pixel(float value, PgmMode mode);
uint8_t png_pixel(float value);

// The image as rows (row 0 at the top), size_x × size_y bytes.
std::vector<uint8_t> map_to_pgm_pixels(const GridMap &map, PgmMode mode);
std::vector<uint8_t> map_to_png_pixels(const GridMap &map);

// Writes a binary PGM (P5, maxval 255, size_x wide, size_y high) and a YAML
// beside it: the same path with the extension (whatever follows the last
// '.' of the file name; none: appended) replaced by ".yaml". The YAML holds
//   image: <pgm file name, relative>   resolution: <m/cell>
//   origin: [x, y, theta]              negate: 0
//   occupied_thresh: 0.65  free_thresh: 0.196  mode: trinary|scale|raw
// `origin_of_cell00` is the world pose of the lower-left corner of cell
// (0, 0) — map_server's "origin" — and is written to the YAML as it is.
// The image name is a YAML double-quoted string (a name with a line break or
// a quote cannot add keys). Both files are one transaction (temporaries,
// renamed together under a directory lock): both or neither, and the pair
// from one run even when two runs write it at once. Throws carmen::FileError
// naming the file on failure and std::invalid_argument for an empty or
// inconsistent map.
void write_pgm_with_yaml(const std::string &pgm_path, const GridMap &map,
                         const GlobalOffset &origin_of_cell00, PgmMode mode = PgmMode::Trinary);
// The same into two outputs the caller commits (of an OutputTransaction).
void write_pgm_with_yaml(AtomicOutput &pgm, AtomicOutput &yaml, const GridMap &map,
                         const GlobalOffset &origin_of_cell00, PgmMode mode = PgmMode::Trinary);
// The YAML's path for a PGM path (see above).
std::string yaml_path_for(const std::string &pgm_path);

// Writes an 8-bit greyscale PNG (no alpha), oriented as above, pixels from
// png_pixel(). Atomic. Throws like write_pgm_with_yaml.
void write_png(const std::string &path, const GridMap &map);
void write_png(AtomicOutput &out, const GridMap &map);

// Writes an 8-bit RGB PNG of width x height pixels from `rgb` (3 bytes a
// pixel, row 0 at the top), atomically (mapdiff's difference picture).
// Throws std::invalid_argument when rgb.size() != 3 * width * height or a
// side is not positive, carmen::FileError naming the file on failure.
void write_rgb_png(const std::string &path, int width, int height, const std::vector<uint8_t> &rgb);
void write_rgb_png(AtomicOutput &out, int width, int height, const std::vector<uint8_t> &rgb);

// ---------------------------------------------------------------------------
// Reading (image_read.cc). Images are lossy: they give back what their grey
// levels can say. Every failure is a carmen::FileError naming the file (and
// the YAML line where there is one).
// ---------------------------------------------------------------------------

// A PNG written by write_png (any PNG: libpng converts it to 8-bit grey):
// kPngUnknown is unknown (-1), any other level v is 1 - v / 255. The
// resolution is 0: a PNG does not carry one.
GridMap read_png(const std::string &path);

// A map_server pair: the PGM (binary P5, maxval up to 255) at `pgm_path` and
// the YAML beside it (yaml_path_for). The YAML is map_server's flat
// "key: value" form (as write_pgm_with_yaml writes it; '#' comments; image
// plain or double-quoted); resolution and origin are required, negate
// (default 0), mode (default trinary), occupied_thresh and free_thresh
// (defaults 0.65 and 0.196) are optional; the PGM read is the one named
// here, not the YAML's image key. Levels are turned back into cells as
// map_server reads them, occ = (255 - v) / 255 (negate 1: v / 255):
//   trinary: occ > occupied_thresh 1.0, occ < free_thresh 0.0, else -1;
//   scale:   kPgmUnknown -1 (write_pgm_with_yaml's unknown), else occ;
//   raw:     kPgmRawUnknown -1, else v / 100 (a level over 100 is an error).
struct PgmMap {
  GridMap grid;
  GlobalOffset origin;  // the YAML's origin: world pose of cell (0, 0)'s lower-left corner
  PgmMode mode = PgmMode::Trinary;
};
PgmMap read_pgm_with_yaml(const std::string &pgm_path);

}  // namespace carmen

#endif  // CARMEN_COMPAT_IMAGE_IO_H
