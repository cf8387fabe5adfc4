// option_schema.h — the one place a component's options are written: one row
// per option {name, type, default, help, check}. The front ends read the rows
// rather than spelling an option again: log2map's flags (CLI11: the flag is
// the name with '-' for '_'), the Python keywords and their checks
// (`_core.option_schema(component)`), the ROS node's parameters, --help and
// the docs' tables. Mapper parameters keep their own table (params.h:
// `param_table()`), which has the carmen.ini keys besides.
//
// The components and where their tables are written, each in the layer that
// owns what the options configure:
//   "session"     vasco::session_option_table()                (engine: a mapping session's backend and budget)
//   "pose_source" vasco::pipeline::pose_source_option_table()  (pipeline: poses from a file, matched to scans)
//   "map_output"  vasco::pipeline::map_output_option_table()   (pipeline: how a finished map is written)
#ifndef VASCO_GPU_OPTION_SCHEMA_H
#define VASCO_GPU_OPTION_SCHEMA_H

#include <string>
#include <string_view>
#include <vector>

namespace vasco {

enum class OptionType {
  Flag,    // true or false; on the command line, present or not
  Whole,   // an integer within [lo, hi]
  Real,    // a finite number within [lo, hi] (lo_open / hi_open: the bound itself is outside)
  Bytes,   // a memory size: on the command line a whole number of MiB, in Python a whole number of
           // bytes (the keyword `<name>_bytes`); default_text is in MiB, 0 means no limit
  Choice,  // one of `choices`
  Text,    // any text (a file name, a topic, a frame)
  WholeList,  // whole numbers within [lo, hi], comma-separated on the command line, a list in Python
};

// The type's name in the schema Python reads: "flag", "whole", "real",
// "bytes", "choice", "text", "whole_list".
const char *option_type_name(OptionType type);

struct OptionSpec {
  std::string name;          // snake_case: the Python keyword and the node's parameter (max_memory)
  OptionType type = OptionType::Text;
  std::string default_text;  // the default as --help and the docs print it ("" : none, or computed)
  std::string help;          // one sentence, what it does and its unit
  std::vector<std::string> choices;  // Choice: the accepted values, the default among them
  double lo = 0, hi = 0;     // Whole, Real: the bounds (both 0: none)
  bool lo_open = false, hi_open = false;

  // The command-line flag: "--" + name with '_' as '-' (--max-memory).
  std::string flag() const;
  // The help with its default, as --help and the docs print it: "help (default: X)";
  // the help alone without a default.
  std::string help_with_default() const;
  // Whether `v` is a valid value of a Whole or Real option.
  bool in_bounds(double v) const;
  // The bounds or choices in words, for an error message: "a number in (0, 1]",
  // "one of: exact, float".
  std::string rule() const;
};

using OptionTable = std::vector<OptionSpec>;

// The row named `name` (snake_case, or its flag); null when there is none.
const OptionSpec *find_option(const OptionTable &table, std::string_view name);
// The row named `name`, which the caller knows is there (a table's own name):
// Error(Internal) when it is not.
const OptionSpec &option_row(const OptionTable &table, std::string_view name);

// The checks a front end runs on a value of the row `spec`, each throwing
// Error(Usage) "<who> <value>: expected <rule>" (`who`: how the caller names
// the option, "cuda_mode", "--threads", "map_logs: threads").
void check_option_choice(const OptionSpec &spec, const std::string &value, const std::string &who);
void check_option_number(const OptionSpec &spec, double value, const std::string &who);

// The options of a mapping session (vasco::Mapper, its C API, Python's
// Mapper and map_logs, log2map's --backend, --cuda-mode, --threads,
// --device, --split-devices, --max-memory, the ROS node's parameters of the
// same names): the backend by the registry's names, its CUDA mode and
// device, cpu_threads' threads, the host-memory budget, and the renders
// auto weighs (backend_choice.h). Written in src/session_options.cc.
const OptionTable &session_option_table();

}  // namespace vasco

#endif  // VASCO_GPU_OPTION_SCHEMA_H
