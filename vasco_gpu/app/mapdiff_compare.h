// mapdiff_compare.h — what mapdiff compares and how it judges: the two maps
// as read (any format of the map-format table), where B lies on A, and the
// verdict with its exit status (DESIGN §4's table). The reports are in
// mapdiff_report.h, the command line in mapdiff_app.h.
#ifndef VASCO_GPU_APP_MAPDIFF_COMPARE_H
#define VASCO_GPU_APP_MAPDIFF_COMPARE_H

#include <cstdint>
#include <optional>
#include <string>

#include "carmen_compat/map_compare.h"
#include "carmen_compat/map_file.h"
#include "carmen_compat/map_format.h"

namespace mapdiff {

struct Options {
  std::string a, b, png;
  int top = 10;
  double tolerance = 0;
  long long max_status_differs = 0;
  double min_class_agreement = 1.0;
  bool quiet = false, json = false, no_offset = false;
  bool png_given = false;    // --png was given (an empty name is refused, not ignored)
  bool tolerant = false;     // a tolerance option was given: judge by the limits
  bool class_limit = false;  // --min-class-agreement was given
};

struct Input {
  std::string path;
  carmen::GridMap grid;
  std::optional<carmen::GlobalOffset> offset;
  std::string sha256;  // of the GRIDMAP payload (carmen_compat/map_digest.h): what goldens are published with
  // The format table's row for the name; nullptr for '-' and a name the
  // table does not know (both read as CARMEN maps).
  const carmen::MapFormatEntry *format = nullptr;
  bool carmen_map() const { return format == nullptr || format->kind == carmen::MapFormatKind::Carmen; }
  bool picture() const { return format != nullptr && format->kind == carmen::MapFormatKind::Picture; }
  bool resolution_borrowed = false;  // a picture's: the other map's resolution
};

// Where B lies on A and why; `compared` is false when the resolutions differ.
struct Alignment {
  int64_t shift_x = 0, shift_y = 0;
  std::string how;
  bool compared = true;
};

struct Verdict {
  int exit_status = 1;
  std::string line;  // "identical", "different: ...", ...
};

// Reads a map argument; every failure becomes a carmen::FileError naming
// the file.
Input load(const std::string &path);
// The digest, once the resolution is final (a picture takes the other map's).
void digest(Input &in);
// A picture has no resolution: it is compared at the other map's.
void borrow_resolution(Input &picture, const Input &other);
// "Identical": what the GRIDMAP chunk holds — size, resolution, cells bit for
// bit. The OFFSET chunk is not part of it (reported separately).
bool identical_grids(const carmen::GridMap &a, const carmen::GridMap &b);
bool same_offset(const std::optional<carmen::GlobalOffset> &a, const std::optional<carmen::GlobalOffset> &b);
// Where B lies on A.
Alignment align(const Input &a, const Input &b, bool identical, bool no_offset);
// The verdict line and exit status.
Verdict judge(const Input &a, const Input &b, bool identical, const Alignment &al,
              const carmen::GridComparison &c, const Options &o);

// printf's rendering of one number.
std::string fmt(const char *format, double v);
// "x .. y .. theta .." or "none".
std::string offset_text(const std::optional<carmen::GlobalOffset> &o);

}  // namespace mapdiff

#endif  // VASCO_GPU_APP_MAPDIFF_COMPARE_H
