#include "map_files.h"

#include <cmath>
#include <ctime>
#include <sstream>

#include "carmen_compat/error.h"
#include "carmen_compat/map_format.h"
#include "carmen_compat/occupancy_grid.h"
#include "vasco_gpu/map_output.h"
#include "vasco_gpu/pipeline/map_output_options.h"
#include "vasco_gpu/pipeline/outputs.h"
#include "vasco_gpu/version.h"

namespace vasco_py {

Map map_from_finished(vasco::FinishedMap &&f, const vasco::GridGeometry &geo) {
  Map m;
  m.origin = vasco::world_origin(f, geo);  // as log2map writes it
  m.grid.size_x = f.size_x;
  m.grid.size_y = f.size_y;
  m.grid.resolution = f.resolution;
  m.grid.cells = std::move(f.cells);
  m.downsample = f.downsample;
  m.min_x = f.min_x;
  m.min_y = f.min_y;
  m.has_origin = true;
  return m;
}

carmen::OccupancyValues occupancy_values(const std::string &mode, double free_thresh, double occupied_thresh) {
  carmen::MapServerOptions o;
  o.mode = vasco::pipeline::occupancy_data_mode(mode, vasco::pipeline::OptionNaming::Keyword);
  o.free_thresh = free_thresh;
  o.occupied_thresh = occupied_thresh;
  return carmen::occupancy_values(o);
}

Map read_map(const std::string &path) {
  carmen::MapRead r = carmen::read_map(path);
  Map m;
  m.grid = std::move(r.grid);
  if (r.origin) {
    m.origin = *r.origin;
    m.has_origin = true;
  }
  return m;
}

void check_cells(const Map &m, const std::string &what) {
  const std::vector<float> &c = m.grid.cells;
  for (size_t i = 0; i < c.size(); ++i) {
    if (carmen::valid_cell_value(c[i])) continue;
    const size_t sy = static_cast<size_t>(m.grid.size_y > 0 ? m.grid.size_y : 1);
    std::ostringstream os;
    os.precision(9);  // a float32 in full: 1.00000012 does not read as 1
    os << what << ": cell (" << i / sy << ", " << i % sy << ") is " << c[i]
       << ": a cell is -1 (unknown), a probability in [0, 1] or an off-limits value in [2, 3]";
    throw carmen::Error(carmen::ErrorCode::BadInput, os.str());
  }
}

namespace {

// A .map stores the resolution as a float, a .pgm's YAML as text; both
// readers refuse one that is not positive and finite.
void check_resolution(const std::string &path, double resolution) {
  const float stored = static_cast<float>(resolution);
  if (std::isfinite(stored) && stored > 0) return;
  std::ostringstream os;
  os << path << ": resolution " << resolution << ": must be a positive number of metres per cell";
  throw carmen::Error(carmen::ErrorCode::BadInput, os.str());
}

carmen::MapToWrite to_write(const Map &m, const std::string &pgm_mode, const std::string &description) {
  carmen::MapToWrite w;
  w.grid = m.grid;
  if (m.has_origin) w.origin = m.origin;
  w.source = "vasco_gpu";
  w.creator_origin = "python";
  w.description = description.empty() ? "vasco_gpu " + std::string(vasco::version()) : description;
  w.time = static_cast<int64_t>(std::time(nullptr));
  const vasco::OptionSpec &mode = vasco::option_row(vasco::pipeline::map_output_option_table(), "mode");
  vasco::check_option_choice(mode, pgm_mode, "write_map: mode");
  carmen::parse_pgm_mode(pgm_mode, &w.pgm_mode);
  return w;
}

}  // namespace

void write_map(const std::string &path, const Map &m, const std::string &pgm_mode, const std::string &description) {
  write_maps({path}, m, pgm_mode, description);
}

void write_maps(const std::vector<std::string> &paths, const Map &m, const std::string &pgm_mode,
                const std::string &description) {
  for (const std::string &path : paths) {
    const carmen::MapFormatEntry &format = carmen::map_format_of(path);
    if (format.kind != carmen::MapFormatKind::Picture) check_resolution(path, m.grid.resolution);
    check_cells(m, path);
  }
  vasco::pipeline::write_map_outputs(paths, to_write(m, pgm_mode, description));
}

}  // namespace vasco_py
