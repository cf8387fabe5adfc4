// log2map_app.h — the log → map command line, as a library: log2map runs
// it on CARMEN logs, and bag2map (the Python package) on ROS bags by handing
// over a reader for its inputs. Both share every option, output, exit
// status and message; only how an input becomes scans differs.
#ifndef VASCO_GPU_TOOLS_LOG2MAP_APP_H
#define VASCO_GPU_TOOLS_LOG2MAP_APP_H

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "vasco_gpu/pipeline/log_input.h"

namespace log2map {

// An option of one tool only (bag2map's --scan-topic): "--NAME VALUE",
// handed to the reader as given.
struct ExtraOption {
  std::string name;  // without the dashes
  std::string help;
  std::string type_name = "VALUE";
};

// What makes one tool of the family.
struct ToolSpec {
  std::string name = "log2map";
  std::string summary;               // the help's first lines
  std::string input_name = "LOG";    // the positional input, as the help names it
  std::string input_help;
  std::vector<ExtraOption> extra_options;
  // The written map's cell (m) when --resolution is not given and nothing
  // sets vasco_resolution (bag2map: 0.05, ROS's usual); 0: CARMEN's keys alone.
  double default_map_resolution = 0;
  // Reads one input (the first or one given with --add) into scans with
  // their stamps and mounts; `values` holds the extra options given (by
  // name), `progress(done, total)` drives the progress bar. Empty: the
  // input is a CARMEN log, read by vasco::load_log_input.
  std::function<vasco::StampedScans(const std::string &path, const std::map<std::string, std::string> &values,
                                    const std::function<void(uint64_t, uint64_t)> &progress)>
      read;
};

// Parses argv (argv[0] is ignored) and runs; returns the exit status: 0
// done, 1 bad input or a runtime error, 2 a usage error. Prints to stderr
// (and stdout for --json) as log2map does.
int run_tool(int argc, const char *const *argv, const ToolSpec &spec);

// log2map's own spec: CARMEN logs.
ToolSpec log2map_spec();

}  // namespace log2map

#endif  // VASCO_GPU_TOOLS_LOG2MAP_APP_H
