// mapped.h — whether a finished map is worth writing, the same rule in
// every front end: a map without a known cell is not written, and the error
// says why nothing was mapped (every range unused, or no beam on the grid).
#ifndef VASCO_GPU_PIPELINE_MAPPED_H
#define VASCO_GPU_PIPELINE_MAPPED_H

#include <cstdint>
#include <string>
#include <vector>

#include "vasco_gpu/scan_batch.h"

namespace vasco {
namespace pipeline {

// The cells of a finished map that are known (not -1).
uint64_t known_cells(const std::vector<float> &cells);

// Why `mapped` (the scans of a run) updated no cell, for the error.
std::string why_nothing_was_mapped(const ScanBatch &mapped);

// Throws carmen::FileError(input, why_nothing_was_mapped(mapped)) when no
// cell of `cells` is known.
void check_mapped(const std::vector<float> &cells, const ScanBatch &mapped, const std::string &input);

}  // namespace pipeline
}  // namespace vasco

#endif  // VASCO_GPU_PIPELINE_MAPPED_H
