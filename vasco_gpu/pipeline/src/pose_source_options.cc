#include "vasco_gpu/pipeline/pose_source_options.h"

#include <algorithm>
#include <limits>

#include "carmen_compat/error.h"
#include "number_text.h"
#include "vasco_gpu/pipeline/log_input.h"
#include "vasco_gpu/pipeline/pose_file.h"
#include "vasco_gpu/pipeline/pose_match.h"

namespace vasco::pipeline {

namespace {

OptionSpec text_row(std::string name, std::string help) {
  OptionSpec o;
  o.name = std::move(name);
  o.type = OptionType::Text;
  o.help = std::move(help);
  return o;
}

OptionSpec choice_row(std::string name, std::string default_text, std::vector<std::string> choices,
                      std::string help) {
  OptionSpec o = text_row(std::move(name), std::move(help));
  o.type = OptionType::Choice;
  o.default_text = std::move(default_text);
  o.choices = std::move(choices);
  return o;
}

// Seconds from 0 up; `finite`: +inf excluded.
OptionSpec seconds_row(std::string name, double default_value, bool finite, std::string help) {
  OptionSpec o = text_row(std::move(name), std::move(help));
  o.type = OptionType::Real;
  o.default_text = number_text(default_value);
  o.lo = 0;
  o.hi = std::numeric_limits<double>::infinity();
  o.hi_open = finite;
  return o;
}

OptionTable make_table() {
  const PoseSource d;  // the defaults
  OptionSpec skip = text_row("skip_unposed", "leave out (and count) scans without a pose instead of stopping");
  skip.type = OptionType::Flag;
  skip.default_text = d.match.skip_unmatched ? "true" : "false";
  const std::string carmen_logs = carmen_log_extensions_text("/") + "[.gz]";
  return {
      text_row("poses", "replace each scan's laser pose by a SLAM back end's: a TUM trajectory, a g2o file "
                        "(VERTEX_SE2) or a CARMEN log"),
      choice_row("pose_format", pose_file_format_name(d.format), {"auto", "tum", "g2o", "carmen"},
                 "the pose file's format: auto (by extension: .g2o, " + carmen_logs + ", else TUM), tum, g2o or "
                 "carmen"),
      choice_row("pose_match", "auto", {"auto", "order", "id", "time"},
                 "how poses meet scans: auto (time when the file has stamps, else order), order (pose i to scan i), "
                 "id (g2o vertex ids) or time (by stamp)"),
      text_row("pose_ids", "g2o vertex id -> scan index pairs ('id scan' lines) for matching by id"),
      seconds_row("pose_max_gap", d.match.max_gap, false,
                  "time matching: a scan between two poses at most this far apart, in s, takes their "
                  "interpolation (inf: any gap)"),
      seconds_row("pose_tolerance", d.match.tolerance, true,
                  "time matching: a scan before the first pose, after the last or in a wider gap takes the "
                  "nearest pose if at most this far, in s"),
      skip,
      choice_row("pose_frame", d.robot_frame ? "robot" : "laser", {"laser", "robot"},
                 "the poses are of the laser or of the robot"),
      text_row("laser_mount", "the laser in the robot's frame (x, y, theta: m, m, rad), for robot poses "
                              "(default: from each scan)"),
  };
}

}  // namespace

const OptionTable &pose_source_option_table() {
  static const OptionTable table = make_table();
  return table;
}

void check_pose_options_given(const std::vector<std::string> &given, bool reader_poses, OptionNaming naming) {
  const OptionTable &table = pose_source_option_table();
  if (std::find(given.begin(), given.end(), "poses") != given.end()) return;
  std::vector<const OptionSpec *> without_poses, needing;
  for (const OptionSpec &row : table) {
    if (row.name == "poses") continue;
    if (reader_poses && (row.name == "laser_mount" || row.name == "skip_unposed")) continue;
    needing.push_back(&row);
    if (std::find(given.begin(), given.end(), row.name) != given.end()) without_poses.push_back(&row);
  }
  if (without_poses.empty()) return;
  const OptionSpec &poses = option_row(table, "poses");
  const std::string file = naming == OptionNaming::Flag ? " FILE" : "=FILE";
  throw carmen::Error(carmen::ErrorCode::Usage,
                      option_names_text(without_poses, naming) + ": the pose options (" +
                          option_names_text(needing, naming) + ") go with " + option_name(poses, naming) + file);
}

const std::vector<std::string> &carmen_log_extensions() {
  static const std::vector<std::string> extensions = {".log", ".clf"};
  return extensions;
}

std::string carmen_log_extensions_text(const std::string &separator) {
  std::string text;
  for (const std::string &e : carmen_log_extensions()) text += (text.empty() ? "" : separator) + e;
  return text;
}

}  // namespace vasco::pipeline
