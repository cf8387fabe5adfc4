// The class Frame: where a full-resolution evidence grid lies.
#include <nanobind/nanobind.h>

#include "bindings.h"
#include "vasco_gpu/grid.h"

namespace vasco_py {

using namespace nb::literals;
using vasco::GridGeometry;

namespace {

constexpr const char *kFrameDoc =
    "Where a full-resolution evidence grid lies: size in cells, resolution,\n"
    "the first scan's heading (theta_offset) and laser position (x0, y0); the\n"
    "grid is centred on (x0, y0). Pass one to Mapper(frame=...) for a fixed frame\n"
    "(size, resolution and theta_offset are used; x0 and y0 come from the first\n"
    "scan, or from Mapper(frame_centre=(x, y)): then centre_given is True and the\n"
    "grid's axes are the world's).";

void init_frame(GridGeometry *self, int size_x, int size_y, double resolution, double theta_offset) {
  auto *g = new (self) GridGeometry();
  g->size_x = size_x;
  g->size_y = size_y;
  g->resolution = resolution;
  g->theta_offset = theta_offset;
}

}  // namespace

void bind_frame(nb::module_ &m) {
  nb::class_<GridGeometry>(m, "Frame", kFrameDoc)
      .def("__init__", &init_frame, "size_x"_a, "size_y"_a, "resolution"_a, "theta_offset"_a = 0.0)
      .def_rw("size_x", &GridGeometry::size_x)
      .def_rw("size_y", &GridGeometry::size_y)
      .def_rw("resolution", &GridGeometry::resolution)
      .def_rw("theta_offset", &GridGeometry::theta_offset)
      .def_rw("x0", &GridGeometry::x0)
      .def_rw("y0", &GridGeometry::y0)
      .def_ro("centre_given", &GridGeometry::centre_given,
              "Whether (x0, y0) is a centre given to Mapper(frame_centre=...), not the first scan's position.")
      .def("world_x", &GridGeometry::world_x, "gx"_a, "World x of the lower-left corner of cell column gx.")
      .def("world_y", &GridGeometry::world_y, "gy"_a, "World y of the lower-left corner of cell row gy.")
      .def("__repr__", [](const GridGeometry &g) {
        return nb::str("Frame(size_x={}, size_y={}, resolution={}, theta_offset={}, x0={}, y0={}{})")
            .format(g.size_x, g.size_y, g.resolution, g.theta_offset, g.x0, g.y0,
                    g.centre_given ? ", centre_given=True" : "");
      });
}

}  // namespace vasco_py
