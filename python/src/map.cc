// The class Map and the functions that read and write map files.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <climits>
#include <filesystem>
#include <memory>
#include <string>
#include <tuple>

#include "arrays.h"
#include "bindings.h"
#include "carmen_compat/error.h"
#include "carmen_compat/atomic_file.h"
#include "map_files.h"
#include "carmen_compat/map_digest.h"
#include "carmen_compat/occupancy_grid.h"
#include "vasco_gpu/pipeline/map_output_options.h"

namespace vasco_py {

using namespace nb::literals;
namespace fs = std::filesystem;
using Origin = std::tuple<double, double, double>;

namespace {

constexpr const char *kMapDoc =
    "A finished occupancy map (or one read from a file).\n\n"
    "``cells`` is a writable 2-D float32 NumPy view of the map's memory, shape (size_x,\n"
    "size_y), x-major as CARMEN stores it: ``cells[x, y]`` is the cell x columns right of and y\n"
    "rows above the lower-left corner; -1 is unknown, else the occupancy probability.\n"
    "``image`` is the same memory seen as a picture (``cells.T[::-1]``: row 0 at the top, +y up),\n"
    "also a view. ``origin`` is the world pose (x, y, theta) of the lower-left corner of cell\n"
    "(0, 0), as CARMEN's OFFSET chunk and map_server's YAML give it.\n\n"
    "``Map(cells, resolution, origin)`` refuses the cells read_map would refuse (BadInputError, a\n"
    "ValueError, naming the first bad cell); values later written into the ``cells`` view are\n"
    "checked when the map is written (write_map) or compared (compare).";

const vasco::OptionSpec &output_row(const char *name) {
  return vasco::option_row(vasco::pipeline::map_output_option_table(), name);
}

// write_map's docstring, its mode from the row (map_output_options.h).
const char *write_map_doc() {
  static const std::string doc =
      "Writes a map, the format chosen by the name: ``.map`` / ``.map.gz`` (CARMEN, with an OFFSET\n"
      "chunk when the map has an origin), ``.pgm`` (ROS map_server image plus a ``.yaml`` beside it;\n"
      "``mode``: " + output_row("mode").help_with_default() + ") or ``.png`` (grey: white free, black\n"
      "occupied, mid grey unknown). Atomic: a failure leaves no file behind. Raises FileError naming the\n"
      "file, and BadInputError (a ValueError) for a map read_map would refuse: a cell that is not -1 or a\n"
      "probability (NaN among them), or, for .map and .pgm, a resolution that is not positive.";
  return doc.c_str();
}

// write_map's signature, the mode's default from the row.
const char *write_map_sig() {
  static const std::string sig = "def write_map(path: str | os.PathLike, map: Map, mode: str = '" +
                                 output_row("mode").default_text + "', description: str = '') -> None";
  return sig.c_str();
}

// A side of a map: CARMEN stores it as an int.
int map_side(size_t n, const char *axis) {
  if (n > static_cast<size_t>(INT_MAX))
    throw carmen::Error(carmen::ErrorCode::TooLarge, std::string("Map: ") + axis + " of " + std::to_string(n) +
                                                         " cells; a map has at most " + std::to_string(INT_MAX));
  return static_cast<int>(n);
}

// Checked before the cells are converted: a broadcast array of a huge shape
// costs nothing until it is made contiguous.
void check_map_shape(nb::handle cells) {
  static nb::handle shape_of = nb::object(nb::module_::import_("numpy").attr("shape")).release();
  nb::tuple shape = nb::cast<nb::tuple>(shape_of(cells));
  if (shape.size() != 2) return;  // as_array says what is wrong
  map_side(nb::cast<size_t>(shape[0]), "size_x");
  map_side(nb::cast<size_t>(shape[1]), "size_y");
}

void init_map(Map *self, nb::handle cells, double resolution, Origin origin) {
  check_map_shape(cells);
  auto a = as_array<float>(cells, "float32", "cells", 2);
  Map mp;
  mp.grid.size_x = map_side(a.shape(0), "size_x");
  mp.grid.size_y = map_side(a.shape(1), "size_y");
  mp.grid.resolution = resolution;
  mp.grid.cells.assign(a.data(), a.data() + a.size());
  check_cells(mp, "Map");  // what read_map would refuse is refused here, not once written
  mp.origin = {std::get<0>(origin), std::get<1>(origin), std::get<2>(origin)};
  mp.has_origin = true;
  new (self) Map(std::move(mp));
}

Array2<float> cells_view(nb::handle_t<Map> self) {
  Map &mp = nb::cast<Map &>(self);
  return Array2<float>(mp.grid.cells.data(), {static_cast<size_t>(mp.grid.size_x), static_cast<size_t>(mp.grid.size_y)},
                       self);
}

Array2<float> image_view(nb::handle_t<Map> self) {
  Map &mp = nb::cast<Map &>(self);
  const int64_t sy = mp.grid.size_y;
  float *last_row = mp.grid.cells.empty() ? nullptr : mp.grid.cells.data() + (sy - 1);
  return Array2<float>(last_row, {static_cast<size_t>(mp.grid.size_y), static_cast<size_t>(mp.grid.size_x)}, self,
                       {-1, sy});
}

void bind_map_cells(nb::class_<Map> &cls) {
  cls.def("__init__", &init_map, "cells"_a, "resolution"_a, "origin"_a = std::make_tuple(0.0, 0.0, 0.0),
          nb::sig("def __init__(self, cells: numpy.typing.ArrayLike, resolution: float, "
                  "origin: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> None"),
          "A map from x-major cells (size_x, size_y), copied into the map. Each cell is -1 (unknown), a\n"
          "probability in [0, 1] or an off-limits value in [2, 3] (what read_map accepts); any other\n"
          "value (NaN and inf among them) is a BadInputError (a ValueError) naming the first such\n"
          "cell (x, y) and its value.")
      .def_prop_ro("cells", &cells_view, nb::rv_policy::reference,
                   nb::sig("def cells(self) -> numpy.typing.NDArray[numpy.float32]"),
                   "(size_x, size_y) float32, x-major (cells[x, y]); a view of the map's memory.")
      .def_prop_ro("image", &image_view, nb::rv_policy::reference,
                   nb::sig("def image(self) -> numpy.typing.NDArray[numpy.float32]"),
                   "(size_y, size_x) float32 view with row 0 at the top (``cells.T[::-1]``), for plotting.");
}

void bind_map_properties(nb::class_<Map> &cls) {
  cls.def_prop_ro("size_x", [](const Map &mp) { return mp.grid.size_x; })
      .def_prop_ro("size_y", [](const Map &mp) { return mp.grid.size_y; })
      .def_prop_ro("shape", [](const Map &mp) { return std::make_tuple(mp.grid.size_x, mp.grid.size_y); })
      .def_prop_rw(
          "resolution", [](const Map &mp) { return mp.grid.resolution; },
          [](Map &mp, double r) { mp.grid.resolution = r; }, "Metres per cell.")
      .def_prop_rw(
          "origin", [](const Map &mp) { return std::make_tuple(mp.origin.x, mp.origin.y, mp.origin.theta); },
          [](Map &mp, Origin o) {
            mp.origin = {std::get<0>(o), std::get<1>(o), std::get<2>(o)};
            mp.has_origin = true;
          },
          "World pose (x, y, theta) of the lower-left corner of cell (0, 0); (0, 0, 0) when unknown.")
      .def_prop_ro("has_origin", [](const Map &mp) { return mp.has_origin; },
                   "False for a CARMEN map without an OFFSET chunk and for PNG images.")
      .def_prop_ro("downsample", [](const Map &mp) { return mp.downsample; },
                   "The block size finish used (1 for maps read from files).")
      .def_prop_ro("offset_cells", [](const Map &mp) { return std::make_pair(mp.min_x, mp.min_y); },
                   "finish's crop offset (min_x, min_y), in downsampled cells.")
      .def(
          "sha256",
          [](const Map &mp) {
            return carmen::gridmap_payload_sha256(mp.grid.size_x, mp.grid.size_y, mp.grid.resolution, mp.grid.cells);
          },
          "SHA-256 of the map's CARMEN GRIDMAP payload (what the golden SHA256SUMS hold).")
      .def("__repr__", [](const Map &mp) {
        return nb::str("Map(size_x={}, size_y={}, resolution={}, origin=({}, {}, {}))")
            .format(mp.grid.size_x, mp.grid.size_y, mp.grid.resolution, mp.origin.x, mp.origin.y, mp.origin.theta);
      });
}

void bind_map_files(nb::module_ &m) {
  m.def(
      "_read_map",
      [](const fs::path &path) {
        nb::gil_scoped_release release;
        return read_map(path.string());
      },
      "path"_a, nb::sig("def _read_map(path: str | os.PathLike) -> Map"),
      "Reads a map in the format its name says (.map, .map.gz, .pgm with its .yaml, .png).");
  m.def(
      "write_map",
      [](const fs::path &path, const Map &mp, const std::string &mode, const std::string &description) {
        nb::gil_scoped_release release;
        write_map(path.string(), mp, mode, description);
      },
      "path"_a, "map"_a, "mode"_a = output_row("mode").default_text, "description"_a = "", nb::sig(write_map_sig()),
      write_map_doc());
  m.def(
      "_write_maps",
      [](const std::vector<std::string> &paths, const Map &mp, const std::string &mode, const std::string &description) {
        nb::gil_scoped_release release;
        write_maps(paths, mp, mode, description);
      },
      "paths"_a, "map"_a, "mode"_a = output_row("mode").default_text, "description"_a = "",
      "write_map to every one of ``paths`` as one transaction: all are written to temporaries, then\n"
      "renamed; a failure touches no output and leaves no temporary.");
  m.def(
      "_occupancy_grid_data",
      [](const Map &mp, const std::string &mode, double free_thresh, double occupied_thresh,
         nb::handle out) -> nb::object {
        const carmen::OccupancyValues values = occupancy_values(mode, free_thresh, occupied_thresh);
        const size_t cells = mp.grid.cells.size();
        if (out.is_none()) {
          // filled in place: a bytes object nobody else holds yet, written without the GIL
          nb::bytes made = nb::steal<nb::bytes>(PyBytes_FromStringAndSize(nullptr, Py_ssize_t(cells)));
          if (!made.is_valid()) throw nb::python_error();
          int8_t *data = reinterpret_cast<int8_t *>(PyBytes_AS_STRING(made.ptr()));
          nb::gil_scoped_release release;
          carmen::occupancy_grid_data(mp.grid, values, data);
          return std::move(made);
        }
        // a writable buffer of the caller's (the node's message data, used again for each map
        // of one size)
        const WritableBytes view(out, "_occupancy_grid_data: out");
        if (view.size() != cells)
          throw carmen::Error(carmen::ErrorCode::Usage, "occupancy grid data: out holds " + std::to_string(view.size()) +
                                                            " bytes, the map has " + std::to_string(cells) + " cells");
        {
          nb::gil_scoped_release release;
          carmen::occupancy_grid_data(mp.grid, values, view.data());
        }
        return nb::borrow(out);
      },
      "map"_a, "mode"_a, "free_thresh"_a, "occupied_thresh"_a, "out"_a = nb::none(),
      "The map as nav_msgs/OccupancyGrid data (int8): rows from the lower-left cell; mode the\n"
      "map_mode: trinary (100 / 0 / -1 by the thresholds, as map_server reads a trinary picture) or\n"
      "scale, also called raw (round(100 p), -1 unknown). carmen_compat/occupancy_grid.h. Into ``out``\n"
      "(a writable buffer of size_x * size_y bytes, returned) when given, else a new bytes object.");
  m.def("_fail_rename_for_testing", &carmen::OutputTransaction::fail_rename_for_testing, "n"_a, "err"_a,
        "Tests only: the n-th rename (1-based) of the next transaction's commit in this process fails\n"
        "with errno ``err``; 0 disarms.");
}

}  // namespace

void bind_map(nb::module_ &m) {
  nb::class_<Map> cls(m, "Map", kMapDoc);
  bind_map_cells(cls);
  bind_map_properties(cls);
  bind_map_files(m);
}

}  // namespace vasco_py
