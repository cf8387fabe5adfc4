// log2map_steps.h — the steps of turning one input into maps, shared by a
// one-input run (log2map_app.cc) and batch mode (log2map_batch.cc): read
// the input into scans and a grid, map them on a Mapper, write the outputs
// as one transaction.
#ifndef VASCO_GPU_TOOLS_LOG2MAP_STEPS_H
#define VASCO_GPU_TOOLS_LOG2MAP_STEPS_H

#include <condition_variable>
#include <mutex>
#include <thread>
#include <cstdint>
#include <string>
#include <vector>

#include "carmen_compat/map_format.h"
#include "log2map_app.h"
#include "log2map_options.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/pipeline/log_input.h"
#include "vasco_gpu/mapper.hpp"

namespace log2map {

// A one-line progress bar on stderr, only when enabled (a terminal).
class ProgressBar {
 public:
  ProgressBar(const char *label, bool enabled) : label_(label), enabled_(enabled) {}
  ~ProgressBar() { done(); }
  ProgressBar(const ProgressBar &) = delete;
  ProgressBar &operator=(const ProgressBar &) = delete;
  void update(uint64_t done_units, uint64_t total);
  void done();

 private:
  const char *label_;
  bool enabled_;
  int last_ = -1;
  bool shown_ = false;
};

// A phase whose progress has no measure (the mapping and finish, the
// writing): once it has lasted half a second, "label  1.3 s" on stderr,
// redrawn five times a second until the phase ends (then erased). Only when
// enabled (a terminal). Its thread only sleeps and prints.
class PhaseTicker {
 public:
  PhaseTicker(std::string label, bool enabled);
  ~PhaseTicker();
  PhaseTicker(const PhaseTicker &) = delete;
  PhaseTicker &operator=(const PhaseTicker &) = delete;

 private:
  void tick();
  std::string label_;
  std::mutex mutex_;
  std::condition_variable stop_cv_;
  bool stop_ = false;
  std::thread thread_;
};

// Whether progress bars are drawn: a terminal on stderr and no --quiet.
bool progress_wanted(const Options &opt);

std::string basename_of(const std::string &path);

// Every file writing `outputs` creates (a .pgm's .yaml too), for the checks
// made before any work.
std::vector<std::string> files_written(const std::vector<std::string> &outputs);

// The backend options of the command line (--cuda-mode, --threads,
// --device, --max-memory; auto's expected renders: 1 for one input, 0 for a
// batch).
vasco::BackendOptions backend_options(const Options &opt);

// What mapping one input produced.
struct RunResult {
  vasco::LogInput input;
  vasco::MapStats stats;
  vasco::FinishedMap map;
  carmen::GlobalOffset origin;  // of the map's cell (0, 0), in the world
  std::string backend;
  size_t scans = 0;  // mapped (the batch itself goes to the mapper)
  uint64_t known = 0;
  double parse_s = 0, map_total_s = 0, finish_s = 0, write_s = 0, total_s = 0;
};

// Parameters (command line > ini > the log's PARAM lines > defaults), the
// scans of `log` (opt.log, or one input of a batch; and of every session,
// with poses from --poses when given) and the grid; `bar` (optional) shows
// the reading. `opt` is shared by every input of a batch, never copied.
vasco::LogInput read_input(const Options &opt, const std::string &log, const ToolSpec &spec, ProgressBar *bar);

// Maps r.input's scans on `mapper` (started over with the input's
// parameters) and finishes the map; r.input.batch is handed to the mapper.
// Throws a carmen::FileError naming `log` when no cell was mapped or the
// grid passes the memory budget.
void map_input(vasco::Mapper &mapper, const std::string &log, RunResult &r);

// Writes r's map to every one of `outputs` as one transaction: all are
// written to temporaries first and renamed only when every one is written,
// so a failure touches no output and leaves no temporary.
void write_outputs(const Options &opt, const std::string &log, const std::vector<std::string> &outputs,
                   const RunResult &r);

}  // namespace log2map

#endif  // VASCO_GPU_TOOLS_LOG2MAP_STEPS_H
