// map_files.h — the Python Map (a grid and its world origin) and how it
// becomes and comes from files, over carmen_compat's map-format registry
// (map_format.h). map_from_finished is library logic carried here until
// vasco's FinishedMap knows its world origin; then it moves there.
#ifndef VASCO_PY_MAP_FILES_H
#define VASCO_PY_MAP_FILES_H

#include <string>
#include <vector>

#include "carmen_compat/map_file.h"
#include "carmen_compat/occupancy_value.h"
#include "vasco_gpu/grid.h"

namespace vasco_py {

struct Map {
  carmen::GridMap grid;
  carmen::GlobalOffset origin;  // world pose of the lower-left corner of cell (0, 0)
  bool has_origin = false;
  int downsample = 1;
  int min_x = 0, min_y = 0;
};

// A finished grid of a session whose frame is `geo`, its cells moved.
Map map_from_finished(vasco::FinishedMap &&f, const vasco::GridGeometry &geo);

// The map at `path`, in the format its name says (FileError naming it).
Map read_map(const std::string &path);

// Writes `m` to `path` in the format its name says. A map a reader would
// refuse is refused first (carmen::Error(BadInput) naming the file): a cell
// that is not a CARMEN cell value (NaN among them), or, for the formats that
// carry one, a resolution that is not a positive finite float.
void write_map(const std::string &path, const Map &m, const std::string &pgm_mode, const std::string &description);
// The same to every one of `paths` as one transaction (the pipeline's
// write_map_outputs): all written, or none touched.
void write_maps(const std::vector<std::string> &paths, const Map &m, const std::string &pgm_mode,
                const std::string &description);

// The per-cell rule of OccupancyGrid data (carmen_compat/occupancy_value.h)
// for a map_mode (map_output_options.h: "trinary", "scale" or its alias
// "raw") and map_server's thresholds; Error(Usage) naming map_mode for
// another mode.
carmen::OccupancyValues occupancy_values(const std::string &mode, double free_thresh, double occupied_thresh);

// Error(BadInput) naming `what` when a cell of `m` is not a CARMEN cell value.
void check_cells(const Map &m, const std::string &what);

}  // namespace vasco_py

#endif  // VASCO_PY_MAP_FILES_H
