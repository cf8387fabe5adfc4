// compare.h — MOVED to carmen_compat/map_compare.h (namespace carmen): map
// comparison needs only the maps, so it sits beside them. This header keeps
// the old name and the vasco:: spellings compiling; new code includes
// carmen_compat/map_compare.h.
#ifndef VASCO_GPU_COMPARE_H
#define VASCO_GPU_COMPARE_H

#include "carmen_compat/map_compare.h"

namespace vasco {

using carmen::Agreement;
using carmen::CellDifference;
using carmen::compare_grids;
using carmen::compare_maps;
using carmen::difference_image_rgb;
using carmen::GridComparison;
using carmen::offset_shift;

}  // namespace vasco

#endif  // VASCO_GPU_COMPARE_H
