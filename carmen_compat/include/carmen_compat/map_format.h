// map_format.h — the map formats, one table: which extension is which
// format, and how each is read and written (Open3D's t/io extension tables
// are the model). Adding a format is one row in map_format.cc and its reader
// and writer (in a file of their own, declared in map_format.cc beside the
// row); every tool, binding and batch reads the table (docs/contributing.md
// walks it).
//
// The rule (file_names.h): the extension decides, compared without regard to
// ASCII case, so "x.PNG" is a PNG and "x.Map.Gz" a gzipped CARMEN map. Every
// tool and binding asks this table, so they all accept the same names.
//
//   .map        CARMEN map: comments, id, CREATOR, GRIDMAP, OFFSET (when known)
//   .map.gz     the same, gzipped
//   .pgm        map_server / nav2 image plus a .yaml beside it (two files)
//   .png+yaml   the same with a PNG: "NAME.png+yaml" names the pair
//               NAME.png + NAME.yaml (no file is called .png+yaml), so that
//               NAME.png alone stays the picture for people; scale mode
//               makes unknown cells transparent
//   .yaml       a map_server YAML: read, the image its "image" key names
//               (PGM or PNG); written, NAME.yaml + NAME.pgm (as .pgm)
//   .png        picture for people (lossy; no resolution, no origin)
#ifndef CARMEN_COMPAT_MAP_FORMAT_H
#define CARMEN_COMPAT_MAP_FORMAT_H

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/image_io.h"
#include "carmen_compat/map_file.h"

namespace carmen {

// The formats other code tells apart by name. A format added later needs no
// value here: its row says MapFormat::Other (the default) and is known by
// its extension.
enum class MapFormat { CarmenMap, CarmenMapGz, PgmYaml, PngYaml, Yaml, Png, Other };

// Everything a writer needs, for every format.
struct MapToWrite {
  GridMap grid;
  // World pose of the lower-left corner of cell (0, 0): the OFFSET chunk of
  // a .map, the YAML's origin of a .pgm ((0, 0, 0) when absent).
  std::optional<GlobalOffset> origin;
  // Who made it, for a .map's comment block and CREATOR chunk:
  std::string author = "vasco_gpu";  // comments' "Map author", CREATOR user
  std::string source;                // comments' "Origin" (log2map: the log's file name)
  std::string creator_origin;        // CREATOR origin; empty: the same as source
  std::string description;           // comments' and CREATOR's description
  int64_t time = 0;                  // seconds since 1970 (0 is written as it is)
  // A map_server pair's (.pgm, .png+yaml, .yaml) mode, thresholds, negate.
  PgmMode pgm_mode = PgmMode::Trinary;
  double occupied_thresh = kOccupiedThresh;
  double free_thresh = kFreeThresh;
  bool negate = false;
};

// What a reader gives back.
struct MapRead {
  GridMap grid;
  std::optional<GlobalOffset> origin;  // as above; none for a PNG or a .map without OFFSET
};

// What a format holds, for the tools that treat kinds alike (mapconvert copies
// a CARMEN map whole; the map_server options apply to MapServer outputs).
enum class MapFormatKind {
  Carmen,     // a CARMEN map file: chunks, comments, the grid and its offset
  MapServer,  // a map_server / nav2 image + YAML pair: grid, resolution, origin, thresholds
  Picture,    // an image for people: the grid only
};

struct MapFormatEntry {
  const char *extension;  // lower case, with the dot: ".map.gz"
  const char *what;       // for help texts
  MapFormatKind kind;
  MapRead (*read)(const std::string &path);
  void (*write)(OutputTransaction &tx, const std::string &path, const MapToWrite &map);
  // Every file writing `path` creates, and every file reading it reads, for a
  // format of several files (a map_server pair); nullptr: the path alone.
  std::vector<std::string> (*files_written)(const std::string &path) = nullptr;
  std::vector<std::string> (*files_read)(const std::string &path) = nullptr;
  MapFormat format = MapFormat::Other;
};

// Every format, in the order help texts list them.
const std::vector<MapFormatEntry> &map_formats();
// ".map, .map.gz, .pgm, .png+yaml, .yaml, .png": for messages.
std::string known_map_extensions();
// Those of one kind: ".pgm, .png+yaml, .yaml" for MapServer.
std::string known_map_extensions(MapFormatKind kind);
// The extensions without their dot ("map", "map.gz", ...): the format names a
// batch's --formats and Python's map_logs take (a batch writes STEM.NAME).
std::vector<std::string> map_format_names();
// "map, map.gz, pgm, png+yaml, yaml, png": those names for messages and help.
std::string known_map_format_names();
// The format named so (map_format_names()); nullptr when none is.
const MapFormatEntry *find_map_format_by_name(const std::string &name);

// The format of `path` by the rule above; nullptr when none matches.
const MapFormatEntry *find_map_format(const std::string &path);
// The same, or carmen::Error(Usage) naming the path and the known extensions.
const MapFormatEntry &map_format_of(const std::string &path);

// Every file writing `path` creates: the path, for a .pgm its .yaml too;
// for NAME.png+yaml NAME.png and NAME.yaml; for NAME.yaml NAME.yaml and
// NAME.pgm. Throws like map_format_of.
std::vector<std::string> map_output_files(const std::string &path);
// Every file reading `path` reads, as far as the names tell: the path, a
// .pgm's .yaml, a .png+yaml's two files, a .yaml and the image it names
// (when the YAML can be read). Throws like map_format_of.
std::vector<std::string> map_input_files(const std::string &path);
// The map_server settings of `m` (its pgm_mode, thresholds, negate).
MapServerOptions map_server_options_of(const MapToWrite &m);

// Reads the map at `path` in its format. Throws carmen::Error(Usage) for an
// unknown extension and carmen::FileError naming the file for a bad one.
MapRead read_map(const std::string &path);
// Writes `map` to `path` in its format, atomically (both files of a .pgm or
// neither). Throws like read_map, and std::invalid_argument for an empty or
// inconsistent grid.
void write_map(const std::string &path, const MapToWrite &map);
// The same as part of the caller's transaction (renamed by tx.commit()).
void write_map(OutputTransaction &tx, const std::string &path, const MapToWrite &map);

}  // namespace carmen

#endif  // CARMEN_COMPAT_MAP_FORMAT_H
