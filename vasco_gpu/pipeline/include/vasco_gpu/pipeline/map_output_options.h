// map_output_options.h — the map-output options (option_schema.h's
// component "map_output"): how a finished map is written. One row per
// option; log2map's flags (--mode, --free-thresh, ...), the Python bindings'
// checks (write_map's mode, OccupancyGrid data's mode), mapconvert and the
// ROS node's parameters read the rows, and their defaults are carmen_compat's
// (image_io.h: MapServerOptions), written once there.
#ifndef VASCO_GPU_PIPELINE_MAP_OUTPUT_OPTIONS_H
#define VASCO_GPU_PIPELINE_MAP_OUTPUT_OPTIONS_H

#include <string>
#include <vector>

#include "carmen_compat/image_io.h"
#include "vasco_gpu/option_schema.h"
#include "vasco_gpu/pipeline/option_values.h"

namespace vasco::pipeline {

// mode, free_thresh, occupied_thresh, negate (a map_server output's: .pgm,
// .png+yaml, .yaml), map_mode (nav_msgs/OccupancyGrid data's values) and
// formats (a batch's outputs of each input: a list of map_format_names()).
const OptionTable &map_output_option_table();

// The rows that set a map_server output (MapServerOptions): mode,
// free_thresh, occupied_thresh, negate.
const std::vector<std::string> &map_server_option_names();

// The map_server options from their values, checked by the rows and by
// carmen::map_server_options_problem (free below occupied, a grey level left
// for unknown, no negate in raw mode): Error(Usage) naming the option as
// `naming` spells it.
carmen::MapServerOptions checked_map_server_options(const std::string &mode, double free_thresh,
                                                    double occupied_thresh, bool negate, OptionNaming naming);

// map_mode's other names, each with the choice it stands for: "raw" is
// "scale" (the values of OccupancyGrid data in scale mode are a raw
// picture's levels, round(100 p): carmen_compat's occupancy_grid.h calls
// the mode raw).
struct ChoiceAlias {
  const char *alias;
  const char *choice;
};
const std::vector<ChoiceAlias> &map_mode_aliases();

// The map_mode `name` means (an alias taken to its choice), as carmen_compat's
// picture mode whose levels the values are: Trinary or Raw. Error(Usage)
// naming the option for any other name.
carmen::PgmMode occupancy_data_mode(const std::string &name, OptionNaming naming);

}  // namespace vasco::pipeline

#endif  // VASCO_GPU_PIPELINE_MAP_OUTPUT_OPTIONS_H
