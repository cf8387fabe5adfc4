// mapdiff_report.h — mapdiff's reports of a comparison (mapdiff_compare.h):
// the text, the JSON object, and the --png picture of the differences with
// its legend (picture_legend.h).
#ifndef VASCO_GPU_APP_MAPDIFF_REPORT_H
#define VASCO_GPU_APP_MAPDIFF_REPORT_H

#include <string>

#include "carmen_compat/map_compare.h"
#include "mapdiff_compare.h"

namespace mapdiff {

// The report on standard output.
void print_text(const Input &a, const Input &b, bool identical, const Alignment &al,
                const carmen::GridComparison &c, const Verdict &v);
void print_json(const Input &a, const Input &b, bool identical, const Alignment &al,
                const carmen::GridComparison &c, const Verdict &v);

// Writes the picture of the overlap with its legend below; false (and a
// note) when there is no overlap. Cells unknown in both are drawn in the
// pictures' unknown colour (carmen::kPictureUnknown), not a grey any p has.
// Sets *width and *height to the picture's size.
bool write_picture(const std::string &path, const Input &a, const Input &b, const Alignment &al,
                   const carmen::GridComparison &c, int *width, int *height);

}  // namespace mapdiff

#endif  // VASCO_GPU_APP_MAPDIFF_REPORT_H
