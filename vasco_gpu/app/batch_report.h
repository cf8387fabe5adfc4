// batch_report.h — what batch mode tells: each input's outcome as it
// happens (a failure on stderr at once, a progress bar over the inputs on a
// terminal), and at the end a table (per input: scans, times, outputs or
// the error) and the rate, or the same as JSON (--json).
#ifndef VASCO_GPU_TOOLS_BATCH_REPORT_H
#define VASCO_GPU_TOOLS_BATCH_REPORT_H

#include <cstddef>
#include <mutex>
#include <string>
#include <vector>

#include "log2map_steps.h"

namespace log2map {

// One input of a batch.
struct BatchEntry {
  std::string input;
  std::vector<std::string> outputs;
  enum class State { Waiting, Done, Failed, NotRun } state = State::Waiting;
  std::string error;  // Failed: why
  std::vector<std::string> warnings;
  size_t scans = 0;
  double parse_s = 0, map_s = 0, write_s = 0;
  // How long its mapper waited, for its read and then for a write slot:
  // a batch whose mappers wait is bound by the pool (batch_bench's stages).
  double wait_s = 0;
};

// Thread-safe: workers report reads and writes, the mapping thread maps.
class BatchReport {
 public:
  BatchReport(const Options &opt, std::vector<BatchEntry> entries);

  void set_backend(const std::string &backend) { backend_ = backend; }
  // The threads that read and write, and the mappers (a thread each).
  void set_threads(int pool, int mappers) {
    pool_threads_ = pool;
    mappers_ = mappers;
  }
  // The run's phases, in seconds: every input's read, where they are read
  // before the first mapper starts (VASCO_BATCH_READ_FIRST; else 0); until
  // the first mapper had started (its backend; the pool reads meanwhile),
  // until the last map was done, and until the last output was written. For --json.
  void set_phases(double read_first_s, double start_s, double mapping_s, double drain_s) {
    read_first_s_ = read_first_s;
    start_s_ = start_s;
    mapping_s_ = mapping_s;
    drain_s_ = drain_s;
  }
  // The input read and mapped (its map not yet written); waited_s: its
  // mapper's wait for the read and for a write slot.
  void mapped(size_t i, const RunResult &r, double waited_s);
  // Its outputs written, or the input failed at any step (said at once).
  void written(size_t i, double write_s);
  void failed(size_t i, const std::string &why);
  // Inputs left out by --fail-fast.
  void not_run(size_t i);

  size_t failures() const;
  // The table (stderr, unless --quiet) or the JSON (stdout, --json); the
  // failed inputs named last.
  void print_end(double total_s);

 private:
  void advance();  // the bar, with mutex_ held
  void print_table(double total_s) const;
  void print_json(double total_s) const;

  const Options &opt_;
  std::vector<BatchEntry> entries_;
  std::string backend_;
  int pool_threads_ = 0, mappers_ = 0;
  double read_first_s_ = 0, start_s_ = 0, mapping_s_ = 0, drain_s_ = 0;
  mutable std::mutex mutex_;
  ProgressBar bar_;
  size_t finished_ = 0;
};

}  // namespace log2map

#endif  // VASCO_GPU_TOOLS_BATCH_REPORT_H
