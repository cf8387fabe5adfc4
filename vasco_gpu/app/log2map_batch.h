// log2map_batch.h — batch mode of the log → map tools (`--out-dir DIR`):
// many inputs mapped in one process, so the backend (a GPU's context and
// scratch) starts once. Inputs are read on a pool of threads while the
// mapper maps the ones read before, outputs written on the same pool; each
// input's outputs are one transaction, and a bad input is reported and
// skipped (--fail-fast: the run stops at it).
#ifndef VASCO_GPU_TOOLS_LOG2MAP_BATCH_H
#define VASCO_GPU_TOOLS_LOG2MAP_BATCH_H

#include <string>
#include <vector>

#include "log2map_app.h"
#include "log2map_options.h"

namespace log2map {

// Maps every one of opt.inputs; returns the exit status: 0 when every
// input was mapped and written, 1 when any failed (each named on stderr).
// Throws for what stops the whole run (a usage error, an output directory
// that cannot be made, a backend that cannot start).
int run_batch(const Options &opt, const ToolSpec &spec);

}  // namespace log2map

#endif  // VASCO_GPU_TOOLS_LOG2MAP_BATCH_H
