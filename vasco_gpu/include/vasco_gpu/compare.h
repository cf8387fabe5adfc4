// compare.h — the accuracy contract's agreement table (DESIGN §4): how a
// backend's map compares with the oracle's.
#ifndef VASCO_GPU_COMPARE_H
#define VASCO_GPU_COMPARE_H

#include <cstdint>
#include <string>
#include <vector>

namespace vasco {

struct Agreement {
  uint64_t cells = 0;            // cells compared
  uint64_t both_known = 0;       // known (not -1) in both maps
  uint64_t status_differs = 0;   // known in one map, unknown in the other
  uint64_t identical = 0;        // bit-identical values
  double max_abs_diff = 0;       // max |a - b| over cells known in both
  uint64_t large_diffs = 0;      // cells known in both with |a - b| > 0.1
  // Class of a cell: occupied (p > 0.5), free (p < 0.5), unknown (-1); a cell
  // of exactly 0.5 is neither occupied nor free and counts as "even".
  uint64_t class_agree = 0;      // same class in both maps
  uint64_t occupied_ref = 0, occupied_agree = 0;
  uint64_t free_ref = 0, free_agree = 0;
  uint64_t unknown_ref = 0, unknown_agree = 0;

  double class_agreement() const { return cells ? double(class_agree) / double(cells) : 1.0; }
  // A one-line summary and a small table, for logs and the closing notes.
  std::string table(const std::string &title) const;
};

// Compares `test` against `ref` (same size, x-major floats). Throws
// std::invalid_argument if the sizes differ.
Agreement compare_maps(const std::vector<float> &ref, const std::vector<float> &test);

}  // namespace vasco

#endif  // VASCO_GPU_COMPARE_H
