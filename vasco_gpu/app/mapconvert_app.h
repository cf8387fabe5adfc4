// mapconvert_app.h — mapconvert's command line, as a library (its main is
// vasco_gpu/tools/mapconvert.cc): converts a map file (CARMEN, or a ROS
// map_server pair) to another format of the map-format table
// (carmen_compat/map_format.h), chosen by the output's extension, or
// describes it (--info, mapconvert_info.h).
#ifndef VASCO_GPU_APP_MAPCONVERT_APP_H
#define VASCO_GPU_APP_MAPCONVERT_APP_H

namespace mapconvert {

// Parses argv (argv[0] is ignored) and runs; returns the exit status: 0
// done, 1 a file could not be read or written (the message names it), 2 a
// usage error.
int run_tool(int argc, const char *const *argv);

}  // namespace mapconvert

#endif  // VASCO_GPU_APP_MAPCONVERT_APP_H
