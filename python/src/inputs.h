// inputs.h — the keywords that say where a Log's scans and poses come from
// (pose files, several sessions), shared by load_log, load_bag and bag2map.
#ifndef VASCO_PY_INPUTS_H
#define VASCO_PY_INPUTS_H

#include <nanobind/nanobind.h>

#include <filesystem>
#include <optional>
#include <string>

#include "vasco_gpu/pipeline/log_input.h"

namespace vasco_py {

namespace nb = nanobind;

// Fills `o` from load_log's arguments: the source, the ini and overrides,
// and the keywords poses, pose_format, pose_match, pose_tolerance,
// pose_max_gap, pose_ids, skip_unposed, pose_frame, laser_mount, transform,
// add (TypeError for any
// other; None means not given).
void fill_input_options(vasco::LogInputOptions &o, const std::string &path,
                        std::optional<std::filesystem::path> param_file, const std::string &robot,
                        std::optional<nb::dict> overrides, nb::kwargs kwargs);

// A session's placement: the second element of load_log's (path, WHAT) and
// Mapper.insert's transform=. "auto" or ("auto", hint) sets auto_transform
// (and hint); (x, y, theta) the transform. UsageError naming `name` else.
void session_transform_of(nb::handle what, vasco::SessionInput &s, const std::string &name);

}  // namespace vasco_py

#endif  // VASCO_PY_INPUTS_H
