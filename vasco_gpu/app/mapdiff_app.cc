// mapdiff's command line (mapdiff_app.h): its options and help, and a run:
// read both maps, align, compare, judge, report (mapdiff_compare.h,
// mapdiff_report.h).
#include "mapdiff_app.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"
#include "carmen_compat/map_compare.h"
#include "carmen_compat/map_format.h"
#include "cli_support.h"
#include "mapdiff_compare.h"
#include "mapdiff_report.h"
#include "vasco_gpu/pipeline/outputs.h"
#include "vasco_gpu/version.h"

namespace mapdiff {
namespace {

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
int parse(int argc, const char *const *argv, Options &o) {
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
  carmen::remove_temporaries_on_signals();  // as every tool: a signal leaves no picture's temporary
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

int run_tool(int argc, const char *const *argv) {
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

}  // namespace mapdiff
