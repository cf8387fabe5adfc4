// mapdiff_app.h — mapdiff's command line, as a library (its main is
// vasco_gpu/tools/mapdiff.cc): compares the GRIDMAP chunks of two maps, for
// regression suites: is today's map the same as yesterday's (bit for bit, or
// within tolerances), and if not, where and by how much (DESIGN §4's table).
// Either map may be in any format of the map-format table (carmen_compat/
// map_format.h): a map_server pair's grid is compared as a GRIDMAP, its
// origin as the OFFSET; a picture (.png) has neither resolution nor origin.
#ifndef VASCO_GPU_APP_MAPDIFF_APP_H
#define VASCO_GPU_APP_MAPDIFF_APP_H

namespace mapdiff {

// Parses argv (argv[0] is ignored) and runs; returns the exit status: 0
// same (or within tolerance), 1 different, 2 a usage error or a file that
// cannot be read (or the --png picture cannot be written), so that a
// regression suite can tell "the map changed" (1) from "the check broke" (2).
int run_tool(int argc, const char *const *argv);

}  // namespace mapdiff

#endif  // VASCO_GPU_APP_MAPDIFF_APP_H
