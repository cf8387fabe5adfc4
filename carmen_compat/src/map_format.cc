// The map-format table (map_format.h) and its readers and writers.
#include "carmen_compat/map_format.h"

#include <stdexcept>

#include "carmen_compat/error.h"
#include "carmen_compat/file_names.h"

namespace carmen {
namespace {

void check_grid(const GridMap &g) {
  if (g.size_x <= 0 || g.size_y <= 0 || g.cells.size() != size_t(g.size_x) * size_t(g.size_y))
    throw std::invalid_argument("the map to write is empty or inconsistent (" + std::to_string(g.size_x) + " x " +
                                std::to_string(g.size_y) + ", " + std::to_string(g.cells.size()) + " cells)");
}

MapRead read_carmen(const std::string &path) {
  MapReadOptions opts;
  opts.named_chunks = NamedChunkReading::Index;  // only the main grid is wanted
  MapFile mf = read_map_file(path, opts);
  if (!mf.gridmap) throw FileError(path, "holds no GRIDMAP chunk: there is no map in it");
  return MapRead{std::move(*mf.gridmap), mf.offset};
}

MapFile carmen_file_of(const MapToWrite &m) {
  MapFile mf;
  mf.comments = standard_map_comments(m.grid.size_x, m.grid.size_y, m.grid.resolution, m.source, m.description,
                                      m.author, m.time);
  CreatorInfo creator;
  creator.user = m.author;
  creator.origin = m.creator_origin.empty() ? m.source : m.creator_origin;
  creator.description = m.description;
  creator.time = m.time;
  mf.creator = creator;
  mf.gridmap = m.grid;
  mf.offset = m.origin;
  return mf;
}

void write_carmen(OutputTransaction &tx, const std::string &path, const MapToWrite &m) {
  write_map_file(tx.add(path), carmen_file_of(m));
}

MapRead read_pgm(const std::string &path) {
  PgmMap p = read_pgm_with_yaml(path);
  return MapRead{std::move(p.grid), p.origin};
}

void write_pgm(OutputTransaction &tx, const std::string &path, const MapToWrite &m) {
  const std::string yaml = yaml_path_for(path);
  if (yaml == path) throw std::invalid_argument(path + ": the image and its YAML would be one file");
  AtomicOutput &pgm = tx.add(path);
  write_pgm_with_yaml(pgm, tx.add(yaml), m.grid, m.origin.value_or(GlobalOffset{}), m.pgm_mode);
}

MapRead read_png_file(const std::string &path) { return MapRead{read_png(path), std::nullopt}; }

void write_png_file(OutputTransaction &tx, const std::string &path, const MapToWrite &m) {
  write_png(tx.add(path), m.grid);
}

}  // namespace

const std::vector<MapFormatEntry> &map_formats() {
  static const std::vector<MapFormatEntry> formats = {
      {MapFormat::CarmenMap, ".map", "CARMEN map", read_carmen, write_carmen},
      {MapFormat::CarmenMapGz, ".map.gz", "CARMEN map, gzipped", read_carmen, write_carmen},
      {MapFormat::PgmYaml, ".pgm", "ROS map_server image with a .yaml beside it", read_pgm, write_pgm},
      {MapFormat::Png, ".png", "8-bit grey picture", read_png_file, write_png_file},
  };
  return formats;
}

std::string known_map_extensions() {
  std::string s;
  for (const MapFormatEntry &f : map_formats()) s += (s.empty() ? "" : ", ") + std::string(f.extension);
  return s;
}

const MapFormatEntry *find_map_format(const std::string &path) {
  for (const MapFormatEntry &f : map_formats())
    if (has_extension(path, f.extension)) return &f;
  return nullptr;
}

const MapFormatEntry &map_format_of(const std::string &path) {
  if (const MapFormatEntry *f = find_map_format(path)) return *f;
  throw Error(ErrorCode::Usage, printable(path) + ": unknown map format: the name must end in one of " +
                                    known_map_extensions() + " (in any case)");
}

std::vector<std::string> map_output_files(const std::string &path) {
  if (map_format_of(path).format == MapFormat::PgmYaml) return {path, yaml_path_for(path)};
  return {path};
}

MapRead read_map(const std::string &path) { return map_format_of(path).read(path); }

void write_map(OutputTransaction &tx, const std::string &path, const MapToWrite &map) {
  const MapFormatEntry &f = map_format_of(path);
  check_grid(map.grid);
  f.write(tx, path, map);
}

void write_map(const std::string &path, const MapToWrite &map) {
  OutputTransaction tx;
  write_map(tx, path, map);
  tx.commit();
}

}  // namespace carmen
