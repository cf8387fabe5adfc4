// backend_choice.h — what the backend "auto" runs, for every caller: log2map
// (--backend auto), vasco::Mapper and its C API, Python's Mapper and
// map_logs, the ROS node and egrid.h's grids all decide by this one rule.
//
// The rule. With C the cell updates of the workload (estimated_cell_updates:
// the cells its used beams cross) and N the renders expected of it, auto runs
// the GPU when one is usable and
//
//     gpu_start + N * C / gpu_rate  <  N * C / (cpu_rate * cores),
//
// else cpu_threads on `cores` cores (the session's threads, or every core).
// The CPU maps from the first instant; the GPU maps far faster once running,
// but only after its start-up (the CUDA context and the kernels' module, a
// few tenths of a second), which a session pays once. The rates and the
// start-up are measured (auto_cost_model()).
//
// N is BackendOptions::expected_renders:
//  - 1, the default: the workload is mapped once. log2map maps a log so, and
//    a Mapper decides at its first insert with that insert's scans as the
//    workload: a Mapper fed a log and finished chooses what log2map chooses
//    for that log (the same C, cores and N).
//  - k > 1: a session that renders its scans again (each render() after a
//    loop closure maps every stored scan anew); k is the caller's estimate.
//  - 0: a workload without end, whose start-up is paid once for many maps
//    (log2map's batch mode and map_logs: many logs on one mapper; the ROS
//    node and egrid.h's grids: scans as they come). The start-up then weighs
//    nothing and the rule is gpu_rate > cpu_rate * cores, which needs no
//    scans: such a session chooses when it is made. So does the registry's
//    make_renderer("auto"), which knows no workload.
#ifndef VASCO_GPU_BACKEND_CHOICE_H
#define VASCO_GPU_BACKEND_CHOICE_H

#include <string>

#include "vasco_gpu/backend.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

// The measured constants of the rule (the table backend_cost_model.txt,
// which bench/batch_bench.py --cost-model-out writes).
struct CostModel {
  double cpu_cells_per_core_second;  // cpu_threads' cell updates a second, per core
  double gpu_cells_per_second;       // the GPU's once running (float mode; exact mode is within 2x)
  double gpu_start_seconds;          // the GPU's start-up in one process, wall clock
};
const CostModel &auto_cost_model();

// The cells the used beams of `scans` cross: each is traced from the laser
// to min(range + wall, range_max), one cell a resolution step.
double estimated_cell_updates(const ScanBatch &scans, const MapperParams &params);

// What auto chose and why.
struct AutoChoice {
  double cell_updates = 0;  // C (0 when N is 0: not needed)
  int cores = 1;
  int renders = 1;          // N; 0: a workload without end
  double cpu_s = 0;         // N renders on cpu_threads (N = 0: one render)
  double gpu_s = 0;         // the start-up and N renders on the GPU (N = 0: one render, no start-up)
  bool gpu_faster = false;  // the rule's verdict, a GPU usable or not
  bool gpu_usable = false;
  std::string backend;      // what runs: "cuda" (gpu_faster and gpu_usable) or "cpu_threads"
  // For the note log2map prints: "4.1e+07 cell updates: about 0.037 s on 16
  // cores, 0.316 s on the GPU (0.31 s of it start-up)"; without a usable GPU
  // no GPU time, and `no_gpu` instead.
  std::string why;
};

// The rule for `cell_updates` on `cores` cores and `renders` renders;
// `no_gpu` says why no GPU is usable (when gpu_usable is false).
AutoChoice choose_auto(double cell_updates, int cores, int renders, bool gpu_usable, const std::string &no_gpu = "");

// The cores cpu_threads runs on with `options` (its threads, or every core).
int auto_cores(const BackendOptions &options);

// The rule with a session's options: its cores, N = options.expected_renders,
// the GPU options.cuda_device's usability (asked only when the rule would
// take it), and `scans` as the workload (null: none, for N = 0).
AutoChoice choose_auto(const ScanBatch *scans, const MapperParams &params, const BackendOptions &options);

}  // namespace vasco

#endif  // VASCO_GPU_BACKEND_CHOICE_H
