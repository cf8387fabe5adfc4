// mapdiff — compares the GRIDMAP chunks of two maps, for regression
// suites: is today's map the same as yesterday's (bit for bit, or within
// tolerances), and if not, where and by how much (DESIGN §4's table). Either
// map may be in any format of the map-format table (carmen_compat/
// map_format.h): a map_server pair's grid is compared as a GRIDMAP, its
// origin as the OFFSET; a picture (.png) has neither resolution nor origin.
//
//   mapdiff [options] A B
//
// Exit 0 same (or within tolerance), 1 different, 2 usage error or a file
// that cannot be read (or the --png picture cannot be written). A regression
// suite can then tell "the map changed" (1) from "the check broke" (2).
// The command line itself lives in mapdiff_app (vasco_gpu/app/).
#include "mapdiff_app.h"

int main(int argc, char **argv) { return mapdiff::run_tool(argc, argv); }
