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
#include "carmen_compat/occupancy_value.h"

namespace carmen {

// map_server's thresholds, written to the YAML and used by Trinary.
constexpr double kOccupiedThresh = 0.65;
// The default free_thresh is 0.196, what ROS 1's map_saver writes, not nav2's
// map_saver default of 0.25: it is what this writer has always written (a
// map made before reads the same), and it keeps map_saver's trinary unknown
// level 205 unknown — 205 reads as occupancy (255 - 205) / 255 = 0.19608,
// which is free under a free_thresh of 0.25. (With a free_thresh above that,
// the writer moves unknown to a level that still reads as unknown: see
// trinary_levels.)
constexpr double kFreeThresh = 0.196;

// Grey levels (0 = black), as written with the default thresholds, negate 0:
//  Trinary: occupied (p > occupied_thresh) 0, free (p < free_thresh) 254,
//           otherwise — unknown or in between — 205 (map_server reads 205 as
//           unknown: (255-205)/255 = 0.196 is neither below free_thresh nor
//           above occupied_thresh).
//  Scale:   round(255 * (1 - p)); unknown: in a PNG a transparent pixel
//           (alpha 0; map_server's scale mode reads any pixel that is not
//           opaque as unknown), in a PGM 205 (a PGM has no alpha channel, so
//           map_server's scale mode cannot express unknown: it reads 205 as
//           occupancy 0.196; only our reader takes 205 back as unknown).
//  Raw:     round(100 * p) (0..100, the occupancy value itself); unknown 255,
//           which map_server's raw mode passes on as -1 in the int8
//           OccupancyGrid; off-limits 100.
// negate 1 writes 255 - level (map_server then reads occupancy v / 255).
enum class PgmMode { Trinary, Scale, Raw };
constexpr uint8_t kPgmOccupied = 0;
constexpr uint8_t kPgmFree = 254;
constexpr uint8_t kPgmUnknown = 205;
constexpr uint8_t kPgmRawUnknown = 255;

// The picture for people (.png): RGB, a known cell grey round(255 * (1 - p))
// (white free, black occupied; off-limits black), an unknown cell the
// grey-green RViz shows unknown space in, #708986, a colour no p gives.
struct PictureRgb {
  uint8_t r, g, b;
};
constexpr PictureRgb kPictureUnknown{0x70, 0x89, 0x86};
// Pictures written before had one grey channel with unknown 128 (the grey
// of p = 0.5 too): read_png still reads such a grey PNG that way.
constexpr uint8_t kPngUnknown = 128;

// How the images read a cell: unknown (NaN or negative: CARMEN's -1),
// off-limits (2 and above), else an occupancy, clamped to [0, 1].
// Inline: the per-cell loops (occupancy_grid.cc) vectorise them.
inline bool is_unknown(float v) { return unknown_cell(v); }  // occupancy_value.h
inline bool is_offlimits(float v) { return v >= 2.0f; }
inline double clamp01(double p) { return p < 0.0 ? 0.0 : (p > 1.0 ? 1.0 : p); }

// std::invalid_argument for a map that is empty or whose cells disagree with
// its size; `what` names what could not be made of it ("an image").
void check_map_size(const GridMap &map, const char *what);

// "trinary", "scale", "raw" (as in the YAML's mode key).
const char *pgm_mode_name(PgmMode mode);
// Parses a mode name; false if it is none of the three.
bool parse_pgm_mode(const std::string &name, PgmMode *mode);

// What a map_server YAML says about its image, and what the writer uses.
struct MapServerOptions {
  PgmMode mode = PgmMode::Trinary;
  double occupied_thresh = kOccupiedThresh;
  double free_thresh = kFreeThresh;
  bool negate = false;
};

// Empty when `o` can be written, else what is wrong, naming the settings by
// the names given (a tool passes its options, "--free-thresh"): each
// threshold a number from 0 to 1, free below occupied, a trinary grey level
// between them for unknown, and no negate in raw mode (ROS 1's map_server
// negates a raw image, nav2's does not: the two would read it differently).
std::string map_server_options_problem(const MapServerOptions &o, const std::string &free_name = "free_thresh",
                                       const std::string &occupied_name = "occupied_thresh",
                                       const std::string &negate_name = "negate");

// The trinary levels for `o`'s thresholds, before negation: occupied 0; free
// 254 (255 when 254 would not read as free: free_thresh <= 1/255); unknown
// 205, or when 205 would not read as unknown under these thresholds, the
// level nearest 205 that does. Throws std::invalid_argument when
// map_server_options_problem says so.
struct TrinaryLevels {
  uint8_t occupied, free, unknown;
};
TrinaryLevels trinary_levels(const MapServerOptions &o);

// The grey level of one cell value (default thresholds, negate 0).
uint8_t pgm_pixel(float value, PgmMode mode);
// The same under `o` (its thresholds, its negate).
uint8_t map_server_pixel(float value, const MapServerOptions &o);
// The grey of a known cell in pictures: round(255 * (1 - p)), off-limits 0;
// kPngUnknown for an unknown one (pictures use kPictureUnknown instead).
uint8_t png_pixel(float value);

// The image as rows (row 0 at the top), size_x × size_y bytes.
std::vector<uint8_t> map_to_pgm_pixels(const GridMap &map, PgmMode mode);
std::vector<uint8_t> map_to_pgm_pixels(const GridMap &map, const MapServerOptions &o);
// The picture, 3 bytes a pixel.
std::vector<uint8_t> map_to_picture_rgb(const GridMap &map);

// The image a map_server YAML goes with.
enum class MapImageKind { Pgm, Png };

// Writes a binary PGM (P5, maxval 255, size_x wide, size_y high) and a YAML
// beside it: the same path with the extension (whatever follows the last
// '.' of the file name; none: appended) replaced by ".yaml". The YAML holds
//   image: <pgm file name, relative>   resolution: <m/cell>
//   origin: [x, y, theta]              negate: 0|1
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
// Any image kind and options: a PGM as above, or a PNG (8-bit grey; grey +
// alpha in scale mode, unknown transparent). The YAML names `image`'s file.
// Throws std::invalid_argument for options map_server_options_problem refuses.
void write_map_server_pair(AtomicOutput &image, AtomicOutput &yaml, const GridMap &map,
                           const GlobalOffset &origin_of_cell00, const MapServerOptions &o, MapImageKind kind);
// The YAML's path for a PGM path (see above).
std::string yaml_path_for(const std::string &pgm_path);

// Writes the picture (RGB PNG, no alpha), oriented as above, colours as
// above. Atomic. Throws like write_pgm_with_yaml.
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

// A picture written by write_png: kPictureUnknown is unknown (-1), any
// other colour the mean m of its channels, 1 - m / 255. A grey PNG (one
// written before pictures had colour, or any other) reads kPngUnknown as
// unknown. The resolution is 0: a PNG does not carry one.
GridMap read_png(const std::string &path);

// A map_server pair: an image and its YAML. The YAML is map_server's flat
// "key: value" form (as write_map_server_pair writes it; '#' comments;
// values plain, double- or single-quoted); resolution and origin are
// required, image too when the image is found through it, negate (default
// 0), mode (default trinary), occupied_thresh and free_thresh (defaults 0.65
// and 0.196) are optional. The image is a binary PGM (P5, maxval up to 255)
// or a PNG, told apart by their first bytes. Pixels are turned into cells as
// map_server reads them: the mean m of the colour channels (in trinary mode
// with the alpha channel averaged in, as both map_servers do), occupancy
// occ = (255 - m) / 255 (negate 1: m / 255), then
//   trinary: occ > occupied_thresh 1.0, occ < free_thresh 0.0, else -1;
//   scale:   unknown (-1) where an image with alpha is not opaque (nav2's
//            rule) or, in an image without alpha, at level 205 (negate:
//            50; write_map_server_pair's unknown), else occ itself (not
//            map_server's 0..100 rescaling between the thresholds: the cell
//            keeps the probability that was written);
//   raw:     255 -1, else m / 100 (a level 101..254 is an error; negate is
//            not applied, as nav2 does not).
struct PgmMap {
  GridMap grid;
  GlobalOffset origin;  // the YAML's origin: world pose of cell (0, 0)'s lower-left corner
  PgmMode mode = PgmMode::Trinary;
  MapServerOptions options;  // the YAML's mode, thresholds and negate
  std::string image_path;    // the image read
};
// The PGM at `pgm_path` and the YAML beside it (yaml_path_for); the image
// read is the one named here, not the YAML's image key.
PgmMap read_pgm_with_yaml(const std::string &pgm_path);
// An image (PGM or PNG) and the YAML given.
PgmMap read_image_with_yaml(const std::string &image_path, const std::string &yaml_path);
// The YAML at `yaml_path` and the image its "image" key names (relative to
// the YAML's directory unless absolute), as map_server loads a map. A bad
// key is a FileError naming the YAML and its line; a missing or unreadable
// image names the image and the YAML line naming it.
PgmMap read_map_server_yaml(const std::string &yaml_path);
// The image path a YAML names, resolved as above. Throws like
// read_map_server_yaml.
std::string map_server_image_of(const std::string &yaml_path);

}  // namespace carmen

#endif  // CARMEN_COMPAT_IMAGE_IO_H
