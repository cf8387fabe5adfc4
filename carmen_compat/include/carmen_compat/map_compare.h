// map_compare.h — the accuracy contract's agreement table (DESIGN §4): how a
// backend's map compares with the oracle's; and the cell-level comparison of
// two CARMEN grids behind the mapdiff tool.
#ifndef CARMEN_COMPAT_MAP_COMPARE_H
#define CARMEN_COMPAT_MAP_COMPARE_H

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "carmen_compat/map_file.h"

namespace carmen {

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

// ---------------------------------------------------------------------------
// Two grids of one resolution, possibly of different sizes and origins.
// B is laid on A so that B's cell (bx, by) covers A's cell (bx + shift_x,
// by + shift_y); all coordinates below are A's.
// ---------------------------------------------------------------------------

// One cell where the maps differ: A's coordinates and both values.
struct CellDifference {
  int x = 0, y = 0;
  float a = 0, b = 0;
};

struct GridComparison {
  int64_t shift_x = 0, shift_y = 0;
  // The overlap, in A's cells: x in [x0, x0 + width), y in [y0, y0 + height).
  // width and height are 0 when the grids do not overlap.
  int x0 = 0, y0 = 0, width = 0, height = 0;
  uint64_t outside = 0;        // cells of A or of B outside the overlap (they count as differing)
  uint64_t outside_known = 0;  // of those, the ones known in their own map
  Agreement agreement;         // over the overlap, A as the reference
  // At most top_n of each: cells known in both whose bits differ, largest
  // |a - b| first (ties in x, then y order); cells known in one map only, in
  // x, then y order.
  std::vector<CellDifference> largest;
  std::vector<CellDifference> status_changes;

  uint64_t differing_cells() const { return agreement.cells - agreement.identical + outside; }
  // Bit-identical over the overlap and nothing outside it.
  bool same_cells() const { return differing_cells() == 0; }
};

// Compares B with A laid as above. The resolutions are not looked at (the
// caller decides whether the grids are comparable). Throws
// std::invalid_argument for a grid whose cells.size() != size_x * size_y.
GridComparison compare_grids(const GridMap &a, const GridMap &b, int64_t shift_x,
                             int64_t shift_y, size_t top_n);

// B's shift onto A from the OFFSET chunks (the world position of the
// lower-left corner of cell (0, 0)): (offset_b - offset_a) / resolution. True
// and the shift when the offsets are finite, both thetas 0 (CARMEN does not
// use theta; a rotated frame is not guessed at) and the difference is a whole
// number of cells (within 1e-6 cell), under 2e9 cells; false and the reason
// in *why otherwise.
bool offset_shift(const GlobalOffset &a, const GlobalOffset &b, double resolution,
                  int64_t *shift_x, int64_t *shift_y, std::string *why);

// The picture of where the maps differ, over the overlap: width x height RGB
// triples, row 0 at the top (highest y), column 0 at x0. A is drawn in grey
// (png_pixel: white free, black occupied, mid grey unknown) where
// the bits are equal. A cell known in both whose bits differ is red
// (255, v, v) where B is higher, blue (v, v, 255) where it is lower, with
// v = round(170 * (1 - s)), s = clamp(1 + log10|dp| / 6, 0, 1): pale for
// |dp| <= 1e-6, full colour for |dp| >= 1. A cell known in A only is magenta
// (255, 0, 255), known in B only green (0, 200, 0).
std::vector<uint8_t> difference_image_rgb(const GridMap &a, const GridMap &b,
                                          const GridComparison &cmp);

}  // namespace carmen

#endif  // CARMEN_COMPAT_MAP_COMPARE_H
