// What mapdiff compares and how it judges (mapdiff_compare.h).
#include "mapdiff_compare.h"

#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include "carmen_compat/error.h"
#include "carmen_compat/map_digest.h"

namespace mapdiff {
namespace {

std::string summary(const carmen::GridComparison &c) {
  const carmen::Agreement &g = c.agreement;
  const uint64_t n = c.differing_cells();
  return std::to_string(n) + (n == 1 ? " cell differs" : " cells differ") + " (max |dp| " + fmt("%.9g", g.max_abs_diff) +
         ", known/unknown differs " + std::to_string(g.status_differs) + ", outside the overlap " +
         std::to_string(c.outside) + ", class agreement " + fmt("%.6f", g.class_agreement()) + ")";
}

// The reasons a comparison is outside the tolerances; empty when within.
// Cells outside the overlap are in one map only, like a known/unknown change,
// so they share --max-status-differs. The class agreement is checked only when
// asked for: every class disagreement is a status change or a value change,
// which the other two limits already bound, so a default of 1.0 would make
// `--max-status-differs 5` fail on the very changes it allows.
std::vector<std::string> tolerance_failures(const carmen::GridComparison &c, const Options &o) {
  std::vector<std::string> f;
  const carmen::Agreement &g = c.agreement;
  if (!(g.max_abs_diff <= o.tolerance))
    f.push_back("max |dp| " + fmt("%.9g", g.max_abs_diff) + " > " + fmt("%.9g", o.tolerance));
  const unsigned long long status = g.status_differs + c.outside;
  if (status > static_cast<unsigned long long>(o.max_status_differs))
    f.push_back("known/unknown differs + outside the overlap " + std::to_string(status) + " > " +
                std::to_string(o.max_status_differs));
  if (o.class_limit && !(g.class_agreement() >= o.min_class_agreement))
    f.push_back("class agreement " + fmt("%.6f", g.class_agreement()) + " < " +
                fmt("%.9g", o.min_class_agreement));
  return f;
}

// Identical GRIDMAPs placed apart in the world are different maps, unless
// told to ignore the OFFSET chunks (a map without one says nothing).
bool offsets_conflict(const Input &a, const Input &b, const Options &o) {
  return !o.no_offset && a.offset && b.offset && !same_offset(a.offset, b.offset);
}

}  // namespace

// Every failure becomes a carmen::FileError naming the file, so main can say
// "mapdiff: PATH: what is wrong" and exit 2. A CARMEN map (and '-', and any
// name the format table does not know) is read as a map file, its GRIDMAP and
// OFFSET chunks; any other format through the table's reader
// (carmen::read_map), its origin taken as the OFFSET.
Input load(const std::string &path) {
  Input in;
  in.path = path;
  in.format = carmen::find_map_format(path);
  try {
    if (in.carmen_map()) {
      carmen::MapFile m = carmen::read_map_file(path);
      if (!m.gridmap) throw carmen::FileError(path, "has no GRIDMAP chunk: nothing to compare");
      in.grid = std::move(*m.gridmap);
      in.offset = m.offset;
    } else {
      carmen::MapRead m = in.format->read(path);
      in.grid = std::move(m.grid);
      in.offset = m.origin;
      // A GRIDMAP stores its resolution as a float32 and a YAML's decimal
      // reads back as a double: compared at a GRIDMAP's precision, a CARMEN
      // map and its map_server conversion have one resolution.
      in.grid.resolution = double(float(in.grid.resolution));
    }
  } catch (const carmen::FileError &) {
    throw;
  } catch (const std::exception &e) {
    throw carmen::FileError(path, e.what());
  }
  return in;
}

// The digest, once the resolution is final (a picture takes the other map's).
void digest(Input &in) {
  in.sha256 = carmen::gridmap_payload_sha256(in.grid.size_x, in.grid.size_y, in.grid.resolution, in.grid.cells);
}

// A picture has no resolution: it is compared at the other map's.
void borrow_resolution(Input &picture, const Input &other) {
  if (!picture.picture() || other.picture()) return;
  picture.grid.resolution = other.grid.resolution;
  picture.resolution_borrowed = true;
}

// "Identical": what the GRIDMAP chunk holds — size, resolution, cells bit for
// bit. The OFFSET chunk is not part of it (reported separately).
bool identical_grids(const carmen::GridMap &a, const carmen::GridMap &b) {
  return a.size_x == b.size_x && a.size_y == b.size_y && a.resolution == b.resolution &&
         a.cells.size() == b.cells.size() &&
         (a.cells.empty() || std::memcmp(a.cells.data(), b.cells.data(), a.cells.size() * sizeof(float)) == 0);
}

bool same_offset(const std::optional<carmen::GlobalOffset> &a, const std::optional<carmen::GlobalOffset> &b) {
  if (!a || !b) return !a && !b;
  return a->x == b->x && a->y == b->y && a->theta == b->theta;
}


// Identical grids are compared cell for cell even when their OFFSETs differ:
// the verdict is about the GRIDMAP, and a shifted origin alone would
// otherwise turn "identical" into a table full of differences.
Alignment align(const Input &a, const Input &b, bool identical, bool no_offset) {
  Alignment al;
  if (a.grid.resolution != b.grid.resolution) {
    al.compared = false;
    al.how = "none: the resolutions differ, cells not compared";
  } else if (identical) {
    al.how = "cell for cell (identical GRIDMAPs)";
  } else if (no_offset) {
    al.how = "at cell (0, 0) (--no-offset)";
  } else if (a.picture() || b.picture()) {
    const char *which = a.picture() && b.picture() ? "both are pictures" : a.picture() ? "A is a picture" : "B is a picture";
    al.how = std::string("at cell (0, 0) (") + which + ": a .png has no origin)";
  } else if (!a.offset || !b.offset) {
    const char *missing = a.offset ? "B" : b.offset ? "A" : "either";
    al.how = std::string("at cell (0, 0) (no OFFSET chunk in ") + missing + ")";
  } else {
    std::string why;
    if (carmen::offset_shift(*a.offset, *b.offset, a.grid.resolution, &al.shift_x, &al.shift_y, &why)) {
      al.how = "by OFFSET: B's cell (0, 0) is A's cell (" + std::to_string(al.shift_x) + ", " +
               std::to_string(al.shift_y) + ")";
    } else {
      al.how = "at cell (0, 0), not by OFFSET: " + why;
    }
  }
  return al;
}

std::string fmt(const char *format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string offset_text(const std::optional<carmen::GlobalOffset> &o) {
  if (!o) return "none";
  char buf[128];
  std::snprintf(buf, sizeof buf, "x %.9g y %.9g theta %.9g", o->x, o->y, o->theta);
  return buf;
}

Verdict judge(const Input &a, const Input &b, bool identical, const Alignment &al,
              const carmen::GridComparison &c, const Options &o) {
  if (!al.compared)
    return {1, "different: resolution " + fmt("%.9g", a.grid.resolution) + " m vs " +
                   fmt("%.9g", b.grid.resolution) + " m (cells not compared)"};
  if (identical && offsets_conflict(a, b, o))
    return {1, "different: identical GRIDMAPs at other places: OFFSET " + offset_text(a.offset) + " vs " +
                   offset_text(b.offset) + " (--no-offset ignores it)"};
  if (identical) return {0, "identical"};
  if (!o.tolerant) return {1, "different: " + summary(c)};
  const std::vector<std::string> f = tolerance_failures(c, o);
  if (f.empty()) return {0, "within tolerance: " + summary(c)};
  std::string line = "outside tolerance: ";
  for (size_t i = 0; i < f.size(); ++i) line += (i ? "; " : "") + f[i];
  return {1, line};
}

}  // namespace mapdiff
