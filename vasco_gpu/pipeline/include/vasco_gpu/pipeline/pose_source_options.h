// pose_source_options.h — the pose-source options (option_schema.h's
// component "pose_source"): where a log's scans get their poses when not
// from the log itself, a SLAM back end's pose file and how it is matched to
// the scans (PoseSource, log_input.h). One row per option; log2map's flags
// (--poses, --pose-format, ...), Python's keywords of load_log and load_bag
// (poses=, pose_format=, ...) and their checks read the rows. Adding a
// pose-source option is one row here, its member in PoseSource, and a test.
#ifndef VASCO_GPU_PIPELINE_POSE_SOURCE_OPTIONS_H
#define VASCO_GPU_PIPELINE_POSE_SOURCE_OPTIONS_H

#include <string>
#include <vector>

#include "vasco_gpu/option_schema.h"
#include "vasco_gpu/pipeline/option_values.h"

namespace vasco::pipeline {

// poses, pose_format, pose_match, pose_ids, pose_max_gap, pose_tolerance,
// skip_unposed, pose_frame, laser_mount. The defaults are PoseSource's
// (log_input.h, pose_match.h), as text.
const OptionTable &pose_source_option_table();

// The rule "pose options go with poses": Error(Usage) when `given` (row
// names) holds an option of the table other than `poses` and not `poses`,
// naming those given as `naming` spells them. A reader that poses its own
// scans (a bag's, from its tf or pose topic: `reader_poses`) takes
// laser_mount and skip_unposed without a pose file.
void check_pose_options_given(const std::vector<std::string> &given, bool reader_poses, OptionNaming naming);

// The endings of CARMEN logs, each also gzipped (NAME.log.gz): what
// pose_format auto reads as a CARMEN log, what log2map's input is.
const std::vector<std::string> &carmen_log_extensions();
// ".log/.clf" (`separator` "/"), ".log, .clf" (", ").
std::string carmen_log_extensions_text(const std::string &separator);

}  // namespace vasco::pipeline

#endif  // VASCO_GPU_PIPELINE_POSE_SOURCE_OPTIONS_H
