// log_input.h — everything log2map (and the golden harness) needs before a
// backend runs, by DESIGN §3: parameters from their three sources, the laser
// scans of the log, the selected run of them, and the grid they are mapped on.
//
// Parameter precedence, the same for every key: command line > ini file >
// the log's own PARAM lines > vasco's defaults. vasco_first_scan and
// vasco_num_scans follow it too: every laser message is read first and the
// run is selected once the log's PARAM lines are known.
#ifndef VASCO_GPU_LOG_INPUT_H
#define VASCO_GPU_LOG_INPUT_H

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "vasco_gpu/grid.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

struct LogInputOptions {
  std::string log;                               // .log, .clf, gzipped if .gz
  std::string param_file;                        // carmen.ini; empty: none
  std::string robot;                             // robot section of the ini
  std::map<std::string, std::string> overrides;  // vasco_KEY -> value (command line)
  bool lenient = false;                          // skip bad lines instead of stopping
  std::function<void(uint64_t, uint64_t)> progress;  // (bytes read, file size)
  // Bytes the scans and PARAM lines kept from the log may take (0: no limit),
  // counted while the log is read: the message that passes it is refused
  // (FileError naming the line, ErrorCode::OutOfMemory) before the rest is
  // read. budget_option: how the user raises it, as the error names it.
  uint64_t memory_budget = 0;
  std::string budget_option = "--max-memory";
};

struct LogInput {
  MapperParams params;                // validated
  ScanBatch batch;                    // the selected scans, in log order
  LogLoadStats load;                  // counts of the whole log
  GridGeometry geo;                   // DESIGN §3 step 2 (size_grid), from the selected scans: the
                                      // frame a Mapper's first insert of `batch` takes (use the
                                      // Mapper's frame() once it has mapped them)
  std::vector<std::string> warnings;  // unknown vasco_* keys and the like
};

// Reads the parameters and the log. Throws carmen::FileError naming the file
// (and line) for bad input: an unreadable or malformed log or ini, a bad
// parameter value, no scans in the selected run, poses too far apart.
LogInput load_log_input(const LogInputOptions &options);

}  // namespace vasco

#endif  // VASCO_GPU_LOG_INPUT_H
