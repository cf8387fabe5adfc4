// option_values.h — how a front end names an option of the pipeline's tables
// (pose_source_options.h, map_output_options.h) in its messages: the command
// line by its flag (--pose-max-gap), Python by its keyword (pose_max_gap).
// The checks themselves are the schema's (option_schema.h:
// check_option_choice, check_option_number), given the name so spelled.
#ifndef VASCO_GPU_PIPELINE_OPTION_VALUES_H
#define VASCO_GPU_PIPELINE_OPTION_VALUES_H

#include <string>
#include <vector>

#include "vasco_gpu/option_schema.h"

namespace vasco::pipeline {

enum class OptionNaming { Flag, Keyword };

// The row's name as `naming` spells it: "--pose-max-gap" or "pose_max_gap".
std::string option_name(const OptionSpec &row, OptionNaming naming);

// "a, b and c": the rows' names as `naming` spells them, in order.
std::string option_names_text(const std::vector<const OptionSpec *> &rows, OptionNaming naming);

}  // namespace vasco::pipeline

#endif  // VASCO_GPU_PIPELINE_OPTION_VALUES_H
