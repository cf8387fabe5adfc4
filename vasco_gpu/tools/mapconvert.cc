// mapconvert: convert a map file (CARMEN, or a ROS map_server pair), or
// describe it.
//
//   mapconvert [--mode M] [--free-thresh F] [--occupied-thresh O] [--negate] IN OUT
//                                                  convert by OUT's extension
//   mapconvert --info IN                           print what the map holds
//
// Exit status: 0 ok, 1 a file could not be read or written (the message
// names it), 2 usage error. The command line itself lives in mapconvert_app
// (vasco_gpu/app/).
#include "mapconvert_app.h"

int main(int argc, char **argv) { return mapconvert::run_tool(argc, argv); }
