// log2map — turns a CARMEN laser log into a map, as CARMEN's evidence grid
// (vasco/egrid.c) would (DESIGN §3).
//
//   log2map [options] LOG OUT [OUT...]
//
// Outputs by extension: .map / .map.gz (CARMEN), .pgm (+ .yaml, ROS
// map_server), .png. Exit 0 ok, 1 bad input or runtime error, 2 usage error.
// The command line itself lives in log2map_app (bag2map runs it too).
#include "log2map_app.h"

int main(int argc, char **argv) { return log2map::run_tool(argc, argv, log2map::log2map_spec()); }
