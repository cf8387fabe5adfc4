// The map-format table (map_format.h) and its readers and writers.
#include "carmen_compat/map_format.h"

#include <climits>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <sstream>
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

// The most cells a GRIDMAP chunk holds: its size field is an int32 counting
// the 10-byte description, the 12-byte header (sizes, resolution) and 4
// bytes a cell, so a chunk stops short of 2 GiB: 536870906 cells (about
// 23170 x 23170). A larger map is refused, naming the file, before any of it
// is written.
constexpr uint64_t kMaxCarmenMapCells = (static_cast<uint64_t>(INT32_MAX) - 10 - 12) / 4;

void write_carmen(OutputTransaction &tx, const std::string &path, const MapToWrite &m) {
  const uint64_t cells = static_cast<uint64_t>(m.grid.size_x) * static_cast<uint64_t>(m.grid.size_y);
  if (cells > kMaxCarmenMapCells)
    throw FileError(path,
                    "a map of " + std::to_string(m.grid.size_x) + " x " + std::to_string(m.grid.size_y) + " = " +
                        std::to_string(cells) + " cells does not fit a CARMEN map: its GRIDMAP chunk holds at most " +
                        std::to_string(kMaxCarmenMapCells) +
                        " cells (2 GiB); write a .pgm instead, or finish at a larger vasco_downsample",
                    ErrorCode::TooLarge);
  // The GRIDMAP header holds the resolution as a float32: one that is not a
  // positive finite float32 would be written as 0 or inf, which no reader
  // (ours included) takes back.
  const float res = static_cast<float>(m.grid.resolution);
  if (!std::isfinite(res) || res <= 0 || !std::isnormal(res)) {
    std::ostringstream os;
    os << "a resolution of " << m.grid.resolution
       << " m per cell does not fit a CARMEN map (a float32 there: 1.2e-38 to 3.4e38 m)";
    throw FileError(path, os.str(), ErrorCode::TooLarge);
  }
  write_map_file(tx.add(path), carmen_file_of(m));
}

MapRead read_pgm(const std::string &path) {
  PgmMap p = read_pgm_with_yaml(path);
  return MapRead{std::move(p.grid), p.origin};
}

// NAME.png+yaml: NAME.png and NAME.yaml.
std::string png_of_pair(const std::string &path) { return path.substr(0, path.size() - std::strlen("+yaml")); }
// NAME.yaml written: NAME.yaml and NAME.pgm.
std::string pgm_of_yaml(const std::string &path) { return path.substr(0, path.size() - std::strlen(".yaml")) + ".pgm"; }

MapRead read_png_pair(const std::string &path) {
  const std::string png = png_of_pair(path);
  PgmMap p = read_image_with_yaml(png, yaml_path_for(png));
  return MapRead{std::move(p.grid), p.origin};
}

MapRead read_yaml(const std::string &path) {
  PgmMap p = read_map_server_yaml(path);
  return MapRead{std::move(p.grid), p.origin};
}

void write_pair(OutputTransaction &tx, const std::string &image_path, const std::string &yaml_path,
                const MapToWrite &m, MapImageKind kind) {
  if (yaml_path == image_path) throw std::invalid_argument(image_path + ": the image and its YAML would be one file");
  AtomicOutput &image = tx.add(image_path);
  write_map_server_pair(image, tx.add(yaml_path), m.grid, m.origin.value_or(GlobalOffset{}),
                        map_server_options_of(m), kind);
}

void write_pgm(OutputTransaction &tx, const std::string &path, const MapToWrite &m) {
  write_pair(tx, path, yaml_path_for(path), m, MapImageKind::Pgm);
}

void write_png_pair(OutputTransaction &tx, const std::string &path, const MapToWrite &m) {
  const std::string png = png_of_pair(path);
  write_pair(tx, png, yaml_path_for(png), m, MapImageKind::Png);
}

void write_yaml(OutputTransaction &tx, const std::string &path, const MapToWrite &m) {
  write_pair(tx, pgm_of_yaml(path), path, m, MapImageKind::Pgm);
}

MapRead read_png_file(const std::string &path) { return MapRead{read_png(path), std::nullopt}; }

void write_png_file(OutputTransaction &tx, const std::string &path, const MapToWrite &m) {
  write_png(tx.add(path), m.grid);
}


// The files of the map_server pairs, besides the path itself.
std::vector<std::string> pgm_files(const std::string &path) { return {path, yaml_path_for(path)}; }
std::vector<std::string> png_pair_files(const std::string &path) {
  return {png_of_pair(path), yaml_path_for(png_of_pair(path))};
}
std::vector<std::string> yaml_files_written(const std::string &path) { return {path, pgm_of_yaml(path)}; }
std::vector<std::string> yaml_files_read(const std::string &path) {
  try {
    return {path, map_server_image_of(path)};
  } catch (const FileError &) {
    return {path};  // reading it will say what is wrong
  }
}

}  // namespace

// {extension, what, kind, read, write, files written, files read, the name
// other code tells it apart by}
const std::vector<MapFormatEntry> &map_formats() {
  static const std::vector<MapFormatEntry> formats = {
      {".map", "CARMEN map", MapFormatKind::Carmen, read_carmen, write_carmen, nullptr, nullptr, MapFormat::CarmenMap},
      {".map.gz", "CARMEN map, gzipped", MapFormatKind::Carmen, read_carmen, write_carmen, nullptr, nullptr,
       MapFormat::CarmenMapGz},
      {".pgm", "ROS map_server / nav2 PGM image with a .yaml beside it", MapFormatKind::MapServer, read_pgm,
       write_pgm, pgm_files, pgm_files, MapFormat::PgmYaml},
      {".png+yaml", "ROS map_server / nav2 pair NAME.png + NAME.yaml", MapFormatKind::MapServer, read_png_pair,
       write_png_pair, png_pair_files, png_pair_files, MapFormat::PngYaml},
      {".yaml", "ROS map_server YAML (read: the image it names; written: with NAME.pgm)", MapFormatKind::MapServer,
       read_yaml, write_yaml, yaml_files_written, yaml_files_read, MapFormat::Yaml},
      {".png", "picture for people (RGB)", MapFormatKind::Picture, read_png_file, write_png_file, nullptr, nullptr,
       MapFormat::Png},
  };
  return formats;
}

std::vector<std::string> map_format_names() {
  std::vector<std::string> names;
  for (const MapFormatEntry &f : map_formats()) names.push_back(f.extension + 1);
  return names;
}

std::string known_map_format_names() {
  std::string s;
  for (const MapFormatEntry &f : map_formats()) s += (s.empty() ? "" : ", ") + std::string(f.extension + 1);
  return s;
}

const MapFormatEntry *find_map_format_by_name(const std::string &name) {
  for (const MapFormatEntry &f : map_formats())
    if (name == f.extension + 1) return &f;
  return nullptr;
}

std::string known_map_extensions(MapFormatKind kind) {
  std::string s;
  for (const MapFormatEntry &f : map_formats())
    if (f.kind == kind) s += (s.empty() ? "" : ", ") + std::string(f.extension);
  return s;
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
  const MapFormatEntry &f = map_format_of(path);
  return f.files_written != nullptr ? f.files_written(path) : std::vector<std::string>{path};
}

std::vector<std::string> map_input_files(const std::string &path) {
  const MapFormatEntry &f = map_format_of(path);
  return f.files_read != nullptr ? f.files_read(path) : std::vector<std::string>{path};
}

MapServerOptions map_server_options_of(const MapToWrite &m) {
  MapServerOptions o;
  o.mode = m.pgm_mode;
  o.occupied_thresh = m.occupied_thresh;
  o.free_thresh = m.free_thresh;
  o.negate = m.negate;
  return o;
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
