// The session's option table (option_schema.h): what a mapping session takes
// (BackendOptions, backend.h), one row per option. log2map's flags, Python's
// Mapper and map_logs keywords and the ROS node's parameters of these names
// read their help, choices, bounds and defaults here.
#include <climits>
#include <string>

#include "vasco_gpu/backend.h"
#include "vasco_gpu/option_schema.h"

namespace vasco {

namespace {

OptionSpec backend_row() {
  OptionSpec o;
  o.name = "backend";
  o.type = OptionType::Choice;
  o.default_text = "auto";
  o.help = "the mapping backend";
  o.choices = backend_names();  // names and aliases, compiled in or not (one that is not says why when run)
  return o;
}

OptionSpec cuda_mode_row() {
  OptionSpec o;
  o.name = "cuda_mode";
  o.type = OptionType::Choice;
  o.default_text = "float";
  o.help = "the cuda backend's arithmetic: float (fastest) or exact (bit-identical to cpu_double)";
  o.choices = {"float", "exact"};
  return o;
}

OptionSpec whole_row(const char *name, const char *default_text, const char *help, double lo, double hi) {
  OptionSpec o;
  o.name = name;
  o.type = OptionType::Whole;
  o.default_text = default_text;
  o.help = help;
  o.lo = lo;
  o.hi = hi;
  return o;
}

OptionSpec split_devices_row() {
  OptionSpec o = whole_row("split_devices", "", "one render split across these CUDA devices, two or more (a band "
                                                "of the grid's columns on each; a device may repeat)", 0, INT_MAX);
  o.type = OptionType::WholeList;
  return o;
}

OptionSpec max_memory_row() {
  OptionSpec o;
  o.name = "max_memory";
  o.type = OptionType::Bytes;
  o.default_text = std::to_string(kDefaultMaxMemoryBytes >> 20);  // in MiB, as the command line takes it
  o.help = "host memory the map may use, in MiB (0: no limit)";
  return o;
}

OptionTable make_table() {
  return {
      backend_row(),
      cuda_mode_row(),
      whole_row("threads", "0", "threads of cpu_threads (0: all cores)", 0, kMaxThreads),
      whole_row("cuda_device", "0", "the CUDA device of the cuda backend", 0, INT_MAX),
      split_devices_row(),
      max_memory_row(),
      whole_row("expected_renders", "1",
                "renders auto weighs the GPU's start-up against: 1, the first insert's scans mapped once (as "
                "log2map); more, a session that renders again; 0, a workload without end (the GPU when usable)",
                0, INT_MAX),
  };
}

}  // namespace

const OptionTable &session_option_table() {
  static const OptionTable table = make_table();
  return table;
}

}  // namespace vasco
