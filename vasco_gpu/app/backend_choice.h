// backend_choice.h — what `--backend auto` runs for one input mapped once:
// the backend expected to finish first. The CPU maps a beam's cells on
// every core from the first instant; the GPU maps them far faster but only
// after its start-up (the CUDA context and the kernels' module, a few
// tenths of a second), which one run pays in full. Batch mode and the
// sessions pay it once, so there auto means the GPU when one is usable.
#ifndef VASCO_GPU_TOOLS_BACKEND_CHOICE_H
#define VASCO_GPU_TOOLS_BACKEND_CHOICE_H

#include <cstdint>
#include <string>

#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"

namespace log2map {

// The cells the used beams of `scans` cross: each is traced from the laser
// to min(range + wall, range_max), one cell a resolution step.
double estimated_cell_updates(const vasco::ScanBatch &scans, const vasco::MapperParams &params);

struct BackendChoice {
  bool gpu = false;
  double cpu_s = 0;  // estimated mapping time on `cores` CPU cores
  double gpu_s = 0;  // estimated start-up plus mapping time on the GPU
  std::string why;   // "4.1e+07 cell updates: about 0.02 s on 16 cores, 0.31 s on the GPU (0.30 s of it start-up)"
};

// The faster of cpu_threads on `cores` cores and the GPU, started now, for
// `cell_updates` cells (the constants are measured: backend_choice.cc).
BackendChoice choose_backend(double cell_updates, int cores);

}  // namespace log2map

#endif  // VASCO_GPU_TOOLS_BACKEND_CHOICE_H
