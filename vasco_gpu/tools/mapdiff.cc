// mapdiff — compares the GRIDMAP chunks of two maps, for regression
// suites: is today's map the same as yesterday's (bit for bit, or within
// tolerances), and if not, where and by how much (DESIGN §4's table). Either
// map may be in any format of the map-format table (carmen_compat/
// map_format.h): a map_server pair's grid is compared as a GRIDMAP, its
// origin as the OFFSET; a picture (.png) has neither resolution nor origin.
//
//   mapdiff [options] A B
//
// Exit 0 same (or within tolerance), 1 different, 2 usage error or a file
// that cannot be read (or the --png picture cannot be written). A regression
// suite can then tell "the map changed" (1) from "the check broke" (2).
#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"
#include "carmen_compat/image_io.h"
#include "carmen_compat/map_file.h"
#include "carmen_compat/map_format.h"
#include "cli_support.h"
#include "vasco_gpu/pipeline/outputs.h"
#include "picture_legend.h"
#include "carmen_compat/map_compare.h"
#include "carmen_compat/map_digest.h"
#include "vasco_gpu/version.h"

namespace {

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

// ---------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------

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

// ---------------------------------------------------------------------------
// Alignment
// ---------------------------------------------------------------------------

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

// ---------------------------------------------------------------------------
// Verdict
// ---------------------------------------------------------------------------

std::string fmt(const char *format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

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

// ---------------------------------------------------------------------------
// Text report
// ---------------------------------------------------------------------------


// A CARMEN map's first line is its path alone; another format's names it.
std::string format_note(const Input &in) {
  if (in.carmen_map()) return "";
  std::string note = std::string(" (") + in.format->what;
  if (in.format->kind == carmen::MapFormatKind::MapServer) note += "; its origin is the offset";
  if (in.resolution_borrowed) note += "; no resolution of its own: the other map's";
  return note + ")";
}

void print_input(const char *label, const Input &in) {
  std::printf("%s: %s%s\n   size %d x %d cells, resolution %.9g m, offset %s\n   GRIDMAP sha256 %s\n", label,
              in.path.c_str(), format_note(in).c_str(), in.grid.size_x, in.grid.size_y, in.grid.resolution,
              offset_text(in.offset).c_str(), in.sha256.c_str());
}

void print_cell(const carmen::CellDifference &d, const carmen::GridComparison &c) {
  std::printf("  (%d, %d)  A %.9g  B %.9g", d.x, d.y, d.a, d.b);
  if (d.a != -1.0f && d.b != -1.0f) std::printf("  dp %+.9g", double(d.b) - double(d.a));
  if (c.shift_x != 0 || c.shift_y != 0)
    std::printf("  [B's cell (%lld, %lld)]", (long long)(d.x - c.shift_x), (long long)(d.y - c.shift_y));
  std::printf("\n");
}

void print_differences(const carmen::GridComparison &c) {
  const carmen::Agreement &g = c.agreement;
  const uint64_t known_differ = g.cells - g.identical - g.status_differs;  // both -1: equal bits
  if (!c.largest.empty()) {
    std::printf("largest |dp| (known in both; %zu of %llu cells that differ):\n", c.largest.size(),
                (unsigned long long)known_differ);
    for (const auto &d : c.largest) print_cell(d, c);
  }
  if (!c.status_changes.empty()) {
    std::printf("known/unknown changes (first %zu of %llu, -1 = unknown):\n", c.status_changes.size(),
                (unsigned long long)g.status_differs);
    for (const auto &d : c.status_changes) print_cell(d, c);
  }
}

void print_comparison(const carmen::GridComparison &c) {
  if (c.width == 0) {
    std::printf("compared: nothing (the grids do not overlap); outside the overlap %llu cells (%llu known)\n",
                (unsigned long long)c.outside, (unsigned long long)c.outside_known);
    return;
  }
  std::printf("compared: %d x %d cells, A's x %d..%d, y %d..%d; outside the overlap %llu cells (%llu known)\n",
              c.width, c.height, c.x0, c.x0 + c.width - 1, c.y0, c.y0 + c.height - 1,
              (unsigned long long)c.outside, (unsigned long long)c.outside_known);
  std::fputs(c.agreement.table("agreement (A reference, B test):").c_str(), stdout);
  print_differences(c);
}

void print_text(const Input &a, const Input &b, bool identical, const Alignment &al,
                const carmen::GridComparison &c, const Verdict &v) {
  print_input("A", a);
  print_input("B", b);
  std::printf("identical: %s (GRIDMAP size, resolution and cells bit for bit)\n", identical ? "yes" : "no");
  if (identical && !same_offset(a.offset, b.offset)) std::printf("note: the OFFSET chunks differ\n");
  std::printf("alignment: %s\n", al.how.c_str());
  if (al.compared) print_comparison(c);
  std::printf("verdict: %s\n", v.line.c_str());
}

// ---------------------------------------------------------------------------
// JSON report
// ---------------------------------------------------------------------------

using cli::json_string;

// JSON has no NaN or infinity.
std::string json_number(double v, const char *format = "%.17g") {
  return std::isfinite(v) ? fmt(format, v) : "null";
}

std::string json_input(const Input &in) {
  std::ostringstream j;
  j << "{\"path\":" << json_string(in.path) << ",\"size_x\":" << in.grid.size_x << ",\"size_y\":" << in.grid.size_y
    << ",\"resolution\":" << json_number(in.grid.resolution) << ",\"offset\":";
  if (in.offset) {
    j << "{\"x\":" << json_number(in.offset->x) << ",\"y\":" << json_number(in.offset->y)
      << ",\"theta\":" << json_number(in.offset->theta) << "}";
  } else {
    j << "null";
  }
  j << ",\"gridmap_sha256\":" << json_string(in.sha256)
    << ",\"format\":" << (in.format != nullptr ? json_string(in.format->extension) : "null") << "}";
  return j.str();
}

std::string json_cells(const std::vector<carmen::CellDifference> &cells) {
  std::string s = "[";
  for (size_t i = 0; i < cells.size(); ++i) {
    const auto &d = cells[i];
    s += (i ? "," : "") + std::string("{\"x\":") + std::to_string(d.x) + ",\"y\":" + std::to_string(d.y) +
         ",\"a\":" + json_number(d.a, "%.9g") + ",\"b\":" + json_number(d.b, "%.9g") + "}";
  }
  return s + "]";
}

std::string json_comparison(const carmen::GridComparison &c) {
  const carmen::Agreement &g = c.agreement;
  std::ostringstream j;
  j << "{\"shift_x\":" << c.shift_x << ",\"shift_y\":" << c.shift_y << ",\"x0\":" << c.x0 << ",\"y0\":" << c.y0
    << ",\"width\":" << c.width << ",\"height\":" << c.height << ",\"outside\":" << c.outside
    << ",\"outside_known\":" << c.outside_known << ",\"cells\":" << g.cells << ",\"both_known\":" << g.both_known
    << ",\"bit_identical\":" << g.identical << ",\"differing_cells\":" << c.differing_cells()
    << ",\"max_abs_dp\":" << json_number(g.max_abs_diff) << ",\"dp_over_0_1\":" << g.large_diffs
    << ",\"status_differs\":" << g.status_differs << ",\"class_agreement\":" << json_number(g.class_agreement())
    << ",\"occupied\":{\"in_a\":" << g.occupied_ref << ",\"agree\":" << g.occupied_agree << "}"
    << ",\"free\":{\"in_a\":" << g.free_ref << ",\"agree\":" << g.free_agree << "}"
    << ",\"unknown\":{\"in_a\":" << g.unknown_ref << ",\"agree\":" << g.unknown_agree << "}"
    << ",\"largest\":" << json_cells(c.largest) << ",\"status_changes\":" << json_cells(c.status_changes) << "}";
  return j.str();
}

void print_json(const Input &a, const Input &b, bool identical, const Alignment &al,
                const carmen::GridComparison &c, const Verdict &v) {
  std::printf("{\"a\":%s,\"b\":%s,\"identical\":%s,\"offsets_equal\":%s,\"alignment\":%s,"
              "\"comparison\":%s,\"verdict\":%s,\"exit\":%d}\n",
              json_input(a).c_str(), json_input(b).c_str(), identical ? "true" : "false",
              same_offset(a.offset, b.offset) ? "true" : "false",
              json_string(al.how).c_str(), al.compared ? json_comparison(c).c_str() : "null",
              json_string(v.line).c_str(), v.exit_status);
}

// ---------------------------------------------------------------------------
// The picture
// ---------------------------------------------------------------------------

bool unknown_cell(float v) { return std::isnan(v) || v < 0.0f; }

// Writes the picture of the overlap with its legend below; false (and a
// note) when there is no overlap. Cells unknown in both are drawn in the
// pictures' unknown colour (carmen::kPictureUnknown), not a grey any p has.
// Sets *width and *height to the picture's size.
bool write_picture(const std::string &path, const Input &a, const Input &b, const Alignment &al,
                   const carmen::GridComparison &c, int *width, int *height) {
  const char *why = !al.compared ? "the resolutions differ" : c.width == 0 ? "the grids do not overlap" : nullptr;
  if (why != nullptr) {
    std::fprintf(stderr, "mapdiff: %s: not written: %s\n", path.c_str(), why);
    return false;
  }
  std::vector<uint8_t> rgb = carmen::difference_image_rgb(a.grid, b.grid, c);
  for (int row = 0; row < c.height; ++row) {
    const int y = c.y0 + c.height - 1 - row;  // row 0 is the top: y points up
    for (int x = c.x0; x < c.x0 + c.width; ++x) {
      const float va = a.grid.cells[size_t(x) * size_t(a.grid.size_y) + size_t(y)];
      const float vb = b.grid.cells[size_t((x - c.shift_x) * int64_t(b.grid.size_y) + (y - c.shift_y))];
      if (!unknown_cell(va) || std::memcmp(&va, &vb, sizeof va) != 0) continue;
      uint8_t *p = rgb.data() + (size_t(row) * size_t(c.width) + size_t(x - c.x0)) * 3;
      p[0] = carmen::kPictureUnknown.r;
      p[1] = carmen::kPictureUnknown.g;
      p[2] = carmen::kPictureUnknown.b;
    }
  }
  picture::DiffLegend legend;
  legend.differing = c.differing_cells();
  legend.identical = legend.differing == 0;
  const picture::Canvas canvas = picture::with_diff_legend(c.width, c.height, rgb, legend);
  carmen::write_rgb_png(path, canvas.width, canvas.height, canvas.rgb);
  *width = canvas.width;
  *height = canvas.height;
  return true;
}

// ---------------------------------------------------------------------------
// Command line
// ---------------------------------------------------------------------------

const char kFooter[] =
    "\nA is the reference, B the test; cells are given in A's coordinates (x, y).\n"
    "Alignment: when both maps have an OFFSET chunk (theta 0) a whole number of\n"
    "cells apart, B is laid on A by it; otherwise at cell (0, 0). Only the overlap\n"
    "is compared; cells outside it count as differing.\n"
    "Formats: A and B may be any map the format table reads (a CARMEN map, '-',\n"
    "and a name of no known format are read as CARMEN maps); a map_server map's\n"
    "origin counts as its OFFSET and its resolution is taken as a float32, as a\n"
    "GRIDMAP stores it. A .png picture has no resolution and no origin: it takes\n"
    "the other map's resolution and is aligned at cell (0, 0).\n"
    "Same: without tolerance options, equal size and resolution and bit-identical\n"
    "cells, and equal OFFSET chunks where both maps have one (unless --no-offset).\n"
    "With any of --tolerance, --max-status-differs, --min-class-agreement:\n"
    "within every limit (an unset --tolerance or --max-status-differs is 0).\n"
    "PNG: the overlap, y up, and a legend below it; where B agrees, A in grey\n"
    "(white free p = 0 .. black occupied p = 1) and unknown in grey-green #708986;\n"
    "red B higher, blue B lower (pale |dp| <= 1e-6 .. full |dp| >= 1, log scale);\n"
    "magenta known in A only, green known in B only. When nothing differs the\n"
    "legend says IDENTICAL. A narrow overlap is widened on the right for the legend.\n"
    "Exit status: 0 same or within tolerance, 1 different, 2 usage error or a file\n"
    "that cannot be read (missing, damaged, no GRIDMAP) or written.";

void add_options(CLI::App &app, Options &o) {
  app.set_version_flag("--version", [] { return std::string("mapdiff (vasco_gpu) ") + vasco::version(); });
  app.add_option("A", o.a, "reference map (" + carmen::known_map_extensions() + "; - for standard input, a CARMEN map)")
      ->required();
  app.add_option("B", o.b, "map to compare with A (- for standard input)")->required();
  app.add_option("--top", o.top, "list the N largest differences (default 10)")
      ->type_name("N")->check(CLI::NonNegativeNumber);
  app.add_option("--tolerance", o.tolerance, "max |dp| over cells known in both (default 0)")
      ->type_name("DP")->check(CLI::NonNegativeNumber);
  app.add_option("--max-status-differs", o.max_status_differs,
                 "max cells known in one map only, or outside the overlap (default 0)")
      ->type_name("N")->check(CLI::NonNegativeNumber);
  app.add_option("--min-class-agreement", o.min_class_agreement,
                 "min fraction of compared cells in the same occupied/free/unknown class, "
                 "e.g. 0.999 (default: not checked)")
      ->type_name("FRAC")->check(CLI::Range(0.0, 1.0));
  app.add_option("--png", o.png, "write a picture of the differences")->type_name("FILE");
  app.add_flag("--no-offset", o.no_offset,
               "ignore OFFSET chunks: align at cell (0, 0), and identical GRIDMAPs are identical wherever they lie");
  app.add_flag("--quiet,-q", o.quiet, "print the verdict line only");
  app.add_flag("--json", o.json, "print the report as one JSON object (not with --quiet)");
  app.footer(kFooter);
}

// Parses the command line; returns -1 to go on, else the exit status.
int parse(int argc, char **argv, Options &o) {
  CLI::App app{"mapdiff: compares the GRIDMAPs of two maps, CARMEN's or any format of the map table "
                  "(exit 0 same, 1 different, 2 error).", "mapdiff"};
  add_options(app, o);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError &e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::fprintf(stderr, "mapdiff: %s\nRun 'mapdiff --help' for usage.\n", e.what());
    return 2;
  }
  if (o.quiet && o.json) {
    std::fprintf(stderr, "mapdiff: --quiet and --json exclude each other\nRun 'mapdiff --help' for usage.\n");
    return 2;
  }
  o.png_given = app.count("--png") > 0;
  if (o.png_given && o.png.empty()) {
    std::fprintf(stderr, "mapdiff: --png needs a file name\nRun 'mapdiff --help' for usage.\n");
    return 2;
  }
  o.class_limit = app.count("--min-class-agreement") > 0;
  o.tolerant = o.class_limit || app.count("--tolerance") + app.count("--max-status-differs") > 0;
  return -1;
}

// Every file reading a map argument reads (a .pgm's .yaml too), so that
// --png can replace none of them.
std::vector<std::string> input_files(const std::string &arg) {
  if (arg == cli::kStdio || carmen::find_map_format(arg) == nullptr) return {arg};
  try {
    return carmen::map_input_files(arg);
  } catch (const std::exception &) {
    return {arg};
  }
}

int run(const Options &o) {
  // The picture's file is checked, and both maps read, before anything is
  // written: a bad input or target leaves no picture.
  if (o.png_given) {
    std::vector<std::string> inputs = input_files(o.a);
    for (const std::string &f : input_files(o.b)) inputs.push_back(f);
    vasco::pipeline::check_outputs(inputs, {o.png});
  }
  if (o.a == cli::kStdio && o.b == cli::kStdio)
    throw carmen::Error(carmen::ErrorCode::Usage, "A and B are both '-': standard input holds one map");
  Input a = load(cli::input_path(o.a));
  Input b = load(cli::input_path(o.b));
  borrow_resolution(a, b);
  borrow_resolution(b, a);
  digest(a);
  digest(b);
  const bool identical = identical_grids(a.grid, b.grid);
  const Alignment al = align(a, b, identical, o.no_offset);
  carmen::GridComparison c;
  if (al.compared) c = carmen::compare_grids(a.grid, b.grid, al.shift_x, al.shift_y, size_t(o.top));
  const Verdict v = judge(a, b, identical, al, c, o);
  int picture_w = 0, picture_h = 0;
  const bool pictured = !o.png.empty() && write_picture(o.png, a, b, al, c, &picture_w, &picture_h);
  if (o.json) {
    print_json(a, b, identical, al, c, v);
  } else if (o.quiet) {
    std::printf("%s\n", v.line.c_str());
  } else {
    print_text(a, b, identical, al, c, v);
    if (pictured)
      std::printf("picture: %s (%d x %d: the %d x %d overlap and its legend)\n", o.png.c_str(), picture_w, picture_h,
                  c.width, c.height);
  }
  return v.exit_status;
}

}  // namespace

int main(int argc, char **argv) {
  Options o;
  const int rc = parse(argc, argv, o);
  if (rc >= 0) return rc;
  try {
    return run(o);
  } catch (const std::exception &e) {  // a carmen::FileError names the file itself
    std::fprintf(stderr, "mapdiff: %s\n", e.what());
  }
  return 2;
}
