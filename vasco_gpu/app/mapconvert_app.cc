// mapconvert's command line (mapconvert_app.h): its usage, options and
// their checks, and a run: a CARMEN map copied whole, any other format
// through the map-format table's reader and writer, or --info.
//
//   mapconvert [--mode M] [--free-thresh F] [--occupied-thresh O] [--negate] IN OUT
//                                                  convert by OUT's extension
//   mapconvert --info IN                           print what the map holds
#include "mapconvert_app.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"
#include "carmen_compat/image_io.h"
#include "carmen_compat/map_file.h"
#include "carmen_compat/map_format.h"
#include "cli_support.h"
#include "mapconvert_info.h"
#include "vasco_gpu/pipeline/map_output_options.h"
#include "vasco_gpu/pipeline/outputs.h"
#include "vasco_gpu/version.h"

namespace mapconvert {
namespace {

using carmen::MapFormatKind;
namespace pl = vasco::pipeline;

const char kUsageHead[] =
    "Usage: mapconvert [-q] [--mode trinary|scale|raw] [--free-thresh F] [--occupied-thresh O]\n"
    "                  [--negate] IN OUT\n"
    "   or: mapconvert --info IN\n"
    "   or: mapconvert --version\n"
    "\n"
    "Converts the map IN to OUT, each in the format its extension says (any case):\n";

const char kUsageNotes[] =
    "A CARMEN map is copied whole (every chunk it reads; HMAP, unknown and repeated\n"
    "chunks are dropped, with a note); a map_server pair gets the map's OFFSET\n"
    "chunk as its origin (else 0 0 0); in scale mode a .png+yaml's unknown cells are\n"
    "transparent, while a PGM cannot say unknown in scale mode: it gets grey 205,\n"
    "which map_server reads as occupancy 0.196. A .yaml IN is the map it describes\n"
    "(its image, PGM or PNG, read the way map_server reads it); a .png is a picture\n"
    "(black occupied, white free, grey in between, unknown grey-green #708986), not\n"
    "an input: it holds no resolution or origin.\n";

// The usage's middle: the map_server options, for the table's MapServer formats.
std::string usage_options() {
  return "Options of the map_server outputs (" + carmen::known_map_extensions(MapFormatKind::MapServer) +
         "), written to the YAML:\n";
}

// The map_server options' lines: their choices and defaults are the
// map_output rows' (pipeline/map_output_options.h), written once there.
std::string usage_option_lines() {
  const vasco::OptionTable &t = pl::map_output_option_table();
  const vasco::OptionSpec &mode = vasco::option_row(t, "mode"), &free_row = vasco::option_row(t, "free_thresh"),
                          &occupied = vasco::option_row(t, "occupied_thresh");
  std::string modes;
  for (size_t i = 0; i < mode.choices.size(); ++i) {
    const std::string &c = mode.choices[i];
    modes += (i == 0 ? "" : i + 1 == mode.choices.size() ? " or " : ", ") + c +
             (c == mode.default_text ? " (default)" : "");
  }
  return "  --mode M             " + modes + " grey levels\n" +
         "  --free-thresh F      p below F is free (default " + free_row.default_text +
         ", what ROS 1's map_saver\n"
         "                       writes; nav2's map_saver writes 0.25)\n"
         "  --occupied-thresh O  p above O is occupied (default " + occupied.default_text + "); 0 <= F < O <= 1\n";
}

const char kUsageOptions[] =
    "  --negate             negate 1: black free, white occupied (not with raw)\n"
    "--info prints the size, resolution, chunks, unknown fraction and value range.\n"
    "-q, --quiet leaves out the notes (chunks not copied); errors are still said.\n"
    "IN '-' reads a CARMEN map from standard input; OUT '-' writes a CARMEN map\n"
    "(.map) to standard output.\n"
    "\n"
    "Exit status: 0 ok, 1 a file could not be read or written, 2 usage error.\n";

// The usage text: its lists of formats are the map-format table's.
const std::string &usage() {
  static const std::string text = [] {
    std::string t = kUsageHead;
    for (const carmen::MapFormatEntry &f : carmen::map_formats()) {
      std::string ext = f.extension;
      ext.resize(std::max<size_t>(ext.size(), 11), ' ');
      t += "  " + ext + f.what + "\n";
    }
    return t + kUsageNotes + usage_options() + usage_option_lines() + kUsageOptions;
  }();
  return text;
}

int usage_error(const std::string &msg) {
  std::fprintf(stderr, "mapconvert: %s\n%s", msg.c_str(), usage().c_str());
  return 2;
}

// The kind of a name's format by the map-format table's rule (file_names.h:
// the extension, any case); none for a name of no format of the table. A
// CARMEN map is copied whole (every chunk); any other format gets the grid
// and its origin through the table's writer.
std::optional<MapFormatKind> kind_of(const std::string &path) {
  const carmen::MapFormatEntry *f = carmen::find_map_format(path);
  if (f == nullptr) return std::nullopt;
  return f->kind;
}

// ".pgm, .png+yaml and .yaml": the extensions of one kind, for a sentence.
std::string extensions_in_words(MapFormatKind kind) {
  std::string s = carmen::known_map_extensions(kind);
  const size_t last = s.rfind(", ");
  if (last != std::string::npos) s.replace(last, 2, " and ");
  return s;
}

// Whether IN is a CARMEN map (read whole, every chunk) rather than a grid
// of the table (a map_server pair).
bool carmen_input(const std::string &path) {
  return path == cli::kStdio || kind_of(path) == MapFormatKind::Carmen;
}

// The command line, parsed.
struct Args {
  bool info = false, mode_given = false, help = false, version = false, quiet = false;
  bool thresholds_given = false;  // --free-thresh, --occupied-thresh or --negate
  carmen::MapServerOptions map_server;
  std::vector<std::string> files;
};

// A threshold: one finite number, the whole text.
bool parse_threshold(const std::string &text, double *out) {
  char *end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

// Parses argv into *a with CLI11 (the tools' one way to read a command line);
// returns 0, or usage_error's code. The options' values are checked here, in
// mapconvert's words; --help prints usage().
int parse_args(int argc, const char *const *argv, Args *a) {
  CLI::App app{"mapconvert", "mapconvert"};
  app.set_help_flag();  // usage() is the help
  app.allow_extras(false);
  std::string mode, free_thresh, occupied_thresh;
  app.add_flag("--help,-h", a->help);
  app.add_flag("--version", a->version);
  app.add_flag("--quiet,-q", a->quiet);
  app.add_flag("--info", a->info);
  app.add_flag("--negate", a->map_server.negate);
  // A repeated option: the last one wins, as it always has here.
  app.add_option("--mode", mode)->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--free-thresh", free_thresh)->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--occupied-thresh", occupied_thresh)->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("files", a->files);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError &e) {
    return usage_error(e.what());
  }
  if (a->help || a->version) return 0;
  const vasco::OptionTable &rows = pl::map_output_option_table();
  if (app.count("--mode")) {
    const vasco::OptionSpec &row = vasco::option_row(rows, "mode");
    if (std::find(row.choices.begin(), row.choices.end(), mode) == row.choices.end() ||
        !carmen::parse_pgm_mode(mode, &a->map_server.mode))
      return usage_error("unknown --mode '" + mode + "' (" + row.rule() + ")");
    a->mode_given = true;
  }
  for (const auto &[name, text, value] : {std::make_tuple("free_thresh", &free_thresh, &a->map_server.free_thresh),
                                          std::make_tuple("occupied_thresh", &occupied_thresh,
                                                          &a->map_server.occupied_thresh)}) {
    const vasco::OptionSpec &row = vasco::option_row(rows, name);
    if (!app.count(row.flag())) continue;
    // A number out of the row's bounds is said by map_server_options_problem
    // below, as for every front end: "--free-thresh 1.5: must be a number from 0 to 1".
    if (!parse_threshold(*text, value)) return usage_error(row.flag() + " '" + *text + "': expected " + row.rule());
    a->thresholds_given = true;
  }
  a->thresholds_given = a->thresholds_given || a->map_server.negate;
  return 0;
}

// Checks the files and options go together; sets *kind for a conversion.
// Returns 0, or usage_error's code.
int check_args(const Args &a, MapFormatKind *kind) {
  if (a.info) {
    if (a.files.size() != 1) return usage_error("--info takes one map file");
    if (a.mode_given || a.thresholds_given)
      return usage_error("--mode, --free-thresh, --occupied-thresh and --negate apply to map_server output, not --info");
    return 0;
  }
  if (a.files.size() != 2) return usage_error(a.files.empty() ? "no files given" : "expected IN and OUT");
  const std::optional<MapFormatKind> out = a.files[1] == cli::kStdio ? MapFormatKind::Carmen : kind_of(a.files[1]);
  if (!out) {
    return usage_error("cannot tell the output format of '" + a.files[1] + "' (use " +
                       carmen::known_map_extensions() + ")");
  }
  *kind = *out;
  if (a.files[0] != cli::kStdio && !kind_of(a.files[0]))
    return usage_error("cannot tell the format of '" + a.files[0] + "' (use " + carmen::known_map_extensions() + ")");
  if (kind_of(a.files[0]) == MapFormatKind::Picture && *kind != MapFormatKind::Picture)
    return usage_error("'" + a.files[0] + "' is a picture (" + carmen::known_map_extensions(MapFormatKind::Picture) +
                       "): it holds no resolution or origin to make a map of; "
                       "convert from the .map, or from a .png+yaml or .yaml pair");
  if ((a.mode_given || a.thresholds_given) && *kind != MapFormatKind::MapServer)
    return usage_error("--mode, --free-thresh, --occupied-thresh and --negate apply to " +
                       extensions_in_words(MapFormatKind::MapServer) + " output only");
  const std::string problem =
      carmen::map_server_options_problem(a.map_server, "--free-thresh", "--occupied-thresh", "--negate");
  if (!problem.empty()) return usage_error(problem);
  return 0;
}

// The creator fields of a map made from `in`.
void describe(carmen::MapToWrite *w, const std::string &in) {
  const size_t slash = in.find_last_of('/');
  w->author = "mapconvert";
  w->source = slash == std::string::npos ? in : in.substr(slash + 1);
  w->description = "converted by mapconvert (vasco_gpu " + std::string(vasco::version()) + ")";
  w->time = static_cast<int64_t>(std::time(nullptr));
}

// Writes `w` to `out` (standard output for "-").
void write_grid(const carmen::MapToWrite &w, const std::string &out) {
  if (out == cli::kStdio) {
    const cli::StdoutFile to_stdout(".map");
    carmen::write_map(to_stdout.path(), w);
    to_stdout.send();
  } else {
    carmen::write_map(out, w);
  }
}

// The map_server outputs' settings (mode, thresholds, negate) of a map to write.
void set_map_server_options(carmen::MapToWrite *w, const carmen::MapServerOptions &o) {
  w->pgm_mode = o.mode;
  w->free_thresh = o.free_thresh;
  w->occupied_thresh = o.occupied_thresh;
  w->negate = o.negate;
}

// Writes map m, read from `in`, to `out` in the format of kind `kind`.
void convert(const std::string &in, const carmen::MapFile &m, const std::string &out, MapFormatKind kind,
             const carmen::MapServerOptions &o, bool quiet) {
  if (kind == MapFormatKind::Carmen && out == cli::kStdio) {
    const cli::StdoutFile to_stdout(".map");
    carmen::write_map_file(to_stdout.path(), m);
    to_stdout.send();
  } else if (kind == MapFormatKind::Carmen) {
    carmen::write_map_file(out, m);
  }
  if (kind == MapFormatKind::Carmen) {
    if (m.unknown_chunks > 0 && !quiet) {
      std::fprintf(stderr, "mapconvert: note: %d chunk(s) of %s not copied (HMAP, unknown or repeated)\n",
                   m.unknown_chunks, in.c_str());
    }
    return;
  }
  if (!m.gridmap) throw carmen::FileError(in, "has no GRIDMAP chunk: there is no image to make");
  carmen::MapToWrite w;
  w.grid = *m.gridmap;
  w.origin = m.offset;
  set_map_server_options(&w, o);
  carmen::write_map(out, w);
}

// A map_server pair (or picture) IN: its grid and origin, to any OUT. A
// CARMEN map OUT gets the standard comments and a CREATOR chunk naming IN,
// and the YAML's origin as its OFFSET chunk.
void convert_grid(const std::string &in, const std::string &out, const carmen::MapServerOptions &o) {
  carmen::MapRead r = carmen::read_map(in);
  carmen::MapToWrite w;
  w.grid = std::move(r.grid);
  w.origin = r.origin;
  set_map_server_options(&w, o);
  describe(&w, in);
  write_grid(w, out);
}


// Reads IN and converts it, or prints what it holds (--info). The outputs
// (a map_server pair's two files) are checked before the map is read: they
// must be replaceable and must not be an input.
void run(const Args &a, MapFormatKind kind) {
  // As every tool: a termination signal removes the temporaries (the
  // output's, and the staged map of '-') before the process ends.
  carmen::remove_temporaries_on_signals();
  if (!a.info && a.files[1] != cli::kStdio) {
    const std::vector<std::string> inputs =
        a.files[0] == cli::kStdio ? std::vector<std::string>{a.files[0]} : carmen::map_input_files(a.files[0]);
    vasco::pipeline::check_outputs(inputs, carmen::map_output_files(a.files[1]));
  }
  if (!a.info && a.files[1] == cli::kStdio) cli::check_stdout_writable("the output '-'");
  if (!carmen_input(a.files[0])) {
    if (a.info) {
      carmen::MapRead r = carmen::read_map(a.files[0]);
      carmen::MapFile m;
      m.gridmap = std::move(r.grid);
      m.offset = r.origin;
      print_info(a.files[0], m, carmen::map_format_of(a.files[0]).what);
    } else {
      convert_grid(a.files[0], a.files[1], a.map_server);
    }
    return;
  }
  // --info lists named GRIDMAP chunks without parsing them: a file of
  // thousands of them costs their headers, not their cells.
  carmen::MapReadOptions read;
  if (a.info) read.named_chunks = carmen::NamedChunkReading::Index;
  const carmen::MapFile m = carmen::read_map_file(cli::input_path(a.files[0]), read);
  if (a.info) {
    print_info(a.files[0], m, nullptr);
  } else {
    convert(a.files[0], m, a.files[1], kind, a.map_server, a.quiet);
  }
}

}  // namespace

int run_tool(int argc, const char *const *argv) {
  Args a;
  if (const int rc = parse_args(argc, argv, &a)) return rc;
  if (a.help) {
    std::fputs(usage().c_str(), stdout);
    return 0;
  }
  if (a.version) {
    std::printf("mapconvert (vasco_gpu) %s\n", vasco::version());
    return 0;
  }
  MapFormatKind kind = MapFormatKind::Carmen;  // set by check_args for a conversion
  if (const int rc = check_args(a, &kind)) return rc;
  try {
    run(a, kind);
    return 0;
  } catch (const carmen::Error &e) {  // names the file itself
    std::fprintf(stderr, "mapconvert: %s\n", e.what());
    return cli::exit_status(e);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "mapconvert: %s: %s\n", a.files[0].c_str(), e.what());
  }
  return 1;
}

}  // namespace mapconvert
