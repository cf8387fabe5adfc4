// align_refine.h — the local refinement after the global search: the
// search's leaf is within half a rotation step and half a cell of a peak of
// its own discrete score; the refinement climbs the continuous score (the
// field interpolated bilinearly, the points where they are rather than at
// their cells' centres) to a fraction of a cell and of the rotation step.
#ifndef VASCO_GPU_SRC_ALIGN_ALIGN_REFINE_H
#define VASCO_GPU_SRC_ALIGN_ALIGN_REFINE_H

#include "align_grids.h"

namespace vasco {
namespace align_detail {

// A candidate in the search's terms: rotation theta about the points'
// centroid, then the centroid at (tx, ty) metres from the reference grid's
// lower-left corner.
struct Placement {
  double theta = 0, tx = 0, ty = 0;
};

struct RefineInput {
  const Field *field = nullptr;
  double h = 0;
  const Points *points = nullptr;
  double c_x = 0, c_y = 0;
};

// The continuous score's sum at `at`.
double continuous_sum(const RefineInput &in, const Placement &at);

// A pattern search from `start` (steps of half `theta_step` and half a cell,
// halved until a 64th of a cell) to a local maximum of continuous_sum;
// never leaves `start` for a worse placement. `sum` gets its sum.
Placement refine(const RefineInput &in, const Placement &start, double theta_step, double *sum);

// At `at`: how many points land on known reference cells, and how many on
// cells of field value 0.5 or more (within about a cell of a wall).
void count_overlap(const RefineInput &in, const Placement &at, int *on_known, int *on_walls);

}  // namespace align_detail
}  // namespace vasco

#endif  // VASCO_GPU_SRC_ALIGN_ALIGN_REFINE_H
