#include "vasco_gpu/pipeline/map_output_options.h"


#include "carmen_compat/error.h"
#include "number_text.h"
#include "carmen_compat/map_format.h"

namespace vasco::pipeline {

namespace {

OptionSpec row(std::string name, OptionType type, std::string default_text, std::string help) {
  OptionSpec o;
  o.name = std::move(name);
  o.type = type;
  o.default_text = std::move(default_text);
  o.help = std::move(help);
  return o;
}

// A probability threshold: a number from 0 to 1.
OptionSpec threshold_row(std::string name, double default_value, std::string help) {
  OptionSpec o = row(std::move(name), OptionType::Real, number_text(default_value), std::move(help));
  o.lo = 0;
  o.hi = 1;
  return o;
}

OptionTable make_table() {
  const carmen::MapServerOptions d;  // the defaults
  const std::string pairs = carmen::known_map_extensions(carmen::MapFormatKind::MapServer);
  OptionSpec mode = row("mode", OptionType::Choice, carmen::pgm_mode_name(d.mode),
                        "grey levels of " + pairs + " outputs: trinary, scale (unknown transparent in a PNG; a PGM "
                        "cannot say unknown in scale mode) or raw");
  mode.choices = {"trinary", "scale", "raw"};
  // The default is what ROS 1's map_saver writes (image_io.h says why).
  OptionSpec free_thresh = threshold_row("free_thresh", d.free_thresh,
                                         "p below it is free: a map_server output's YAML free_thresh (the default is "
                                         "ROS 1's map_saver's; nav2's map_saver writes 0.25)");
  OptionSpec occupied_thresh = threshold_row("occupied_thresh", d.occupied_thresh,
                                             "p above it is occupied: a map_server output's YAML occupied_thresh");
  OptionSpec negate = row("negate", OptionType::Flag, d.negate ? "true" : "false",
                          "map_server outputs: negate 1 (black free, white occupied; not with mode raw)");
  OptionSpec map_mode = row("map_mode", OptionType::Choice, "trinary",
                            "OccupancyGrid values: trinary (0/100/-1 by the thresholds) or scale (round(100 p), -1 "
                            "unknown; also called raw)");
  map_mode.choices = {"trinary", "scale"};
  OptionSpec formats = row("formats", OptionType::Text, "map.gz",
                           "batch mode: the outputs of each input, a comma-separated list of " +
                               carmen::known_map_format_names());
  formats.choices = carmen::map_format_names();  // each item of the list is one of them
  return {mode, free_thresh, occupied_thresh, negate, map_mode, formats};
}

}  // namespace

const OptionTable &map_output_option_table() {
  static const OptionTable table = make_table();
  return table;
}

const std::vector<std::string> &map_server_option_names() {
  static const std::vector<std::string> names = {"mode", "free_thresh", "occupied_thresh", "negate"};
  return names;
}

carmen::MapServerOptions checked_map_server_options(const std::string &mode, double free_thresh,
                                                    double occupied_thresh, bool negate, OptionNaming naming) {
  const OptionTable &t = map_output_option_table();
  carmen::MapServerOptions o;
  const OptionSpec &mode_row = option_row(t, "mode"), &free_row = option_row(t, "free_thresh"),
                   &occupied_row = option_row(t, "occupied_thresh");
  check_option_choice(mode_row, mode, option_name(mode_row, naming));
  check_option_number(free_row, free_thresh, option_name(free_row, naming));
  check_option_number(occupied_row, occupied_thresh, option_name(occupied_row, naming));
  carmen::parse_pgm_mode(mode, &o.mode);
  o.free_thresh = free_thresh;
  o.occupied_thresh = occupied_thresh;
  o.negate = negate;
  const std::string problem =
      carmen::map_server_options_problem(o, option_name(free_row, naming), option_name(occupied_row, naming),
                                         option_name(option_row(t, "negate"), naming));
  if (!problem.empty()) throw carmen::Error(carmen::ErrorCode::Usage, problem);
  return o;
}

const std::vector<ChoiceAlias> &map_mode_aliases() {
  static const std::vector<ChoiceAlias> aliases = {{"raw", "scale"}};
  return aliases;
}

carmen::PgmMode occupancy_data_mode(const std::string &name, OptionNaming naming) {
  std::string choice = name;
  for (const ChoiceAlias &a : map_mode_aliases())
    if (name == a.alias) choice = a.choice;
  const OptionSpec &r = option_row(map_output_option_table(), "map_mode");
  std::string aliases;
  for (const ChoiceAlias &a : map_mode_aliases()) aliases += std::string(" (") + a.alias + ": " + a.choice + ")";
  for (const std::string &c : r.choices)
    if (c == choice) return c == "trinary" ? carmen::PgmMode::Trinary : carmen::PgmMode::Raw;
  throw carmen::Error(carmen::ErrorCode::Usage,
                      option_name(r, naming) + " '" + carmen::printable(name) + "': expected " + r.rule() + aliases);
}

}  // namespace vasco::pipeline
