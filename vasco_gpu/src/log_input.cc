#include "vasco_gpu/internal/log_input.h"

#include <stdexcept>
#include <utility>

#include "carmen_compat/error.h"
#include "carmen_compat/ini_file.h"

namespace vasco {

LogInput load_log_input(const LogInputOptions &options) {
  LogInput in;
  carmen::ParamFile params;
  if (!options.param_file.empty()) params = carmen::ParamFile::load(options.param_file, options.robot);
  for (const auto &kv : options.overrides) params.set_override(kv.first, kv.second);
  for (const auto &w : params.warnings()) in.warnings.push_back(w.str());
  // Validates the ini and the command line now, before a long log is read.
  MapperParams::from_params(params, nullptr);

  // Every laser message: the run is selected below, once the log's own
  // PARAM lines (which may set vasco_first_scan / vasco_num_scans) are known.
  MapperParams all;
  all.first_scan = 0;
  all.num_scans = -1;
  carmen::LogReaderOptions reader;
  reader.strict = !options.lenient;
  reader.memory_budget = options.memory_budget;
  reader.budget_option = options.budget_option;
  reader.budget_types = carmen::message_type_bit(carmen::MessageType::FLASER) |  // what load_scans keeps
                        carmen::message_type_bit(carmen::MessageType::ROBOTLASER1) |
                        carmen::message_type_bit(carmen::MessageType::PARAM);
  ScanBatch every = load_scans(options.log, all, reader, &in.load, options.progress);
  for (size_t i = 0; i < in.load.params.size(); ++i)
    params.add_fallback(in.load.params[i].first, in.load.params[i].second, options.log,
                        in.load.param_lines[i]);
  in.params = MapperParams::from_params(params, &in.warnings);

  in.batch = std::move(every).select(in.params.first_scan, in.params.num_scans);  // no copy of the ranges
  in.load.scans_used = static_cast<long>(in.batch.num_scans());
  if (in.batch.num_scans() == 0)
    throw carmen::FileError(
        options.log, "no FLASER or ROBOTLASER1 scans to map" +
                         std::string(in.load.laser_messages > 0
                                         ? " in the selected range (vasco_first_scan " +
                                               std::to_string(in.params.first_scan) + " of " +
                                               std::to_string(in.load.laser_messages) + " laser messages)"
                                         : ""));
  try {
    in.geo = size_grid(in.batch, in.params);  // the frame a Mapper's first insert of in.batch takes
  } catch (const carmen::Error &e) {
    throw carmen::FileError(options.log, e.what(), e.code());
  }
  // A block larger than the grid leaves nothing to finish: say so, naming
  // where the value came from.
  if (in.params.downsample > in.geo.size_x || in.params.downsample > in.geo.size_y) {
    const std::string m = "vasco_downsample = " + std::to_string(in.params.downsample) + " is larger than the grid (" +
                          std::to_string(in.geo.size_x) + " x " + std::to_string(in.geo.size_y) +
                          " cells): the finished map would be empty";
    const auto where = params.find("vasco_downsample");
    if (where && where->line > 0) throw carmen::FileError(where->file, where->line, m);
    throw carmen::FileError(where ? where->file : options.log, m);
  }
  return in;
}

}  // namespace vasco
