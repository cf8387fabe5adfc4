#include "log2map_options.h"

#include <CLI/CLI.hpp>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "carmen_compat/error.h"
#include "carmen_compat/map_format.h"
#include "cli_support.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/option_schema.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/pipeline/map_output_options.h"
#include "vasco_gpu/pipeline/outputs.h"
#include "vasco_gpu/pipeline/pose_source_options.h"
#include "vasco_gpu/version.h"

namespace log2map {

namespace {

using carmen::Error;
using carmen::ErrorCode;
using vasco::OptionSpec;
using vasco::OptionType;
namespace pl = vasco::pipeline;

// One number in the C locale, the whole text.
bool parse_double(const std::string &text, double *out) {
  const char *b = text.data(), *e = b + text.size();
  if (b != e && *b == '+') ++b;
  const auto r = std::from_chars(b, e, *out);
  return r.ec == std::errc() && r.ptr == e && b != e;
}

// An option of the pipeline's tables (pose_source_options.h,
// map_output_options.h): its flag, help, default and check from its row.
std::string flag_help(const OptionSpec &row) {
  return row.type == OptionType::Flag ? row.help : row.help_with_default();
}

// CLI11's check of a row's value: one of the choices, or a number within
// the bounds (the tables live as long as the program: `row` outlives it).
CLI::Validator row_check(const OptionSpec &row) {
  if (row.type == OptionType::Choice) return CLI::IsMember(row.choices);
  return CLI::Validator(
      [&row](std::string &v) -> std::string {
        double d = 0;
        return parse_double(v, &d) && row.in_bounds(d) ? std::string() : "expected " + row.rule() + ", not " + v;
      },
      "");
}

template <typename T>
CLI::Option *add_row_option(CLI::App &app, const OptionSpec &row, T &target, const std::string &type_name = "") {
  CLI::Option *o = app.add_option(row.flag(), target, flag_help(row));
  if (!type_name.empty()) o->type_name(type_name);
  if (row.type == OptionType::Choice || row.type == OptionType::Real || row.type == OptionType::Whole)
    o->check(row_check(row));
  return o;
}

CLI::Option *add_row_flag(CLI::App &app, const OptionSpec &row, bool &target) {
  return app.add_flag(row.flag(), target, flag_help(row));
}

// The names of `table`'s rows whose flags were given.
std::vector<std::string> given_rows(const CLI::App &app, const vasco::OptionTable &table) {
  std::vector<std::string> given;
  for (const OptionSpec &row : table)
    if (app.count(row.flag()) > 0) given.push_back(row.name);
  return given;
}

void add_input_options(CLI::App &app, const ToolSpec &spec, Options &opt) {
  app.add_option(spec.input_name, opt.log, spec.input_help + "; - for standard input")->required();
  app.add_option("OUT", opt.outputs,
                 "output files: " + carmen::known_map_extensions() + "; - for a CARMEN map on standard output "
                 "(with --out-dir: "
                 "further " + spec.input_name + "s)");
  app.add_option("--param-file", opt.param_file, "carmen.ini with vasco_* keys (default: vasco's defaults)");
  app.add_option("--robot", opt.robot, "robot section of the ini to use");
}

// What --out-dir takes along; checked after parsing.
struct BatchText {
  std::string formats = vasco::option_row(pl::map_output_option_table(), "formats").default_text;
  std::string devices;
  std::string split_devices;  // not batch mode: one render's GPUs
};

void add_batch_options(CLI::App &app, const ToolSpec &spec, Options &opt, BatchText &raw) {
  app.add_option("--out-dir", opt.out_dir,
                 "batch mode: map every " + spec.input_name + " given, in one process, to DIR/NAME.FORMAT")
      ->type_name("DIR");
  add_row_option(app, vasco::option_row(pl::map_output_option_table(), "formats"), raw.formats, "LIST");
  app.add_flag("--fail-fast", opt.fail_fast, "batch mode: stop at the first input that fails (default: report it, go on)");
  app.add_option("--jobs", opt.jobs, "batch mode: threads reading inputs and writing maps (default: all cores)")
      ->check(CLI::Range(0, vasco::kMaxThreads));
  app.add_option("--devices", raw.devices,
                 "batch mode: the GPUs to map on, a mapper each, e.g. 0,1 (a GPU named twice runs two mappers on it; "
                 "default: every usable GPU, three mappers each)")
      ->type_name("LIST");
  app.add_option("--split-devices", raw.split_devices,
                 "one map rendered across GPUs, the grid's columns in a band on each, e.g. 0,1: the same bytes as one "
                 "GPU (a GPU named twice holds two bands; cuda only, not with --out-dir)")
      ->type_name("LIST");
}

// "0,1,1": the GPUs of --devices or --split-devices (`option`), each a
// whole number (repeats allowed).
std::vector<int> parse_devices(const std::string &text, const char *option) {
  std::vector<int> devices;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    const std::string d = text.substr(start, comma - start);
    int v = -1;
    const auto r = std::from_chars(d.data(), d.data() + d.size(), v);
    if (d.empty() || r.ec != std::errc() || r.ptr != d.data() + d.size() || v < 0 || devices.size() >= 64)
      throw Error(ErrorCode::Usage,
                  std::string(option) + " '" + text + "': expected GPU numbers such as 0,1 (at most 64)");
    devices.push_back(v);
    start = comma + 1;
  }
  return devices;
}

// The map_server outputs' options (their rows in map_output_options.h);
// checked after parsing.
struct MapServerText {
  std::string mode = vasco::option_row(pl::map_output_option_table(), "mode").default_text;
};

void add_map_server_options(CLI::App &app, Options &opt, MapServerText &raw) {
  carmen::MapServerOptions &o = opt.map_server;
  const vasco::OptionTable &t = pl::map_output_option_table();
  add_row_option(app, vasco::option_row(t, "mode"), raw.mode);
  // The thresholds' bounds are checked after parsing (checked_map_server_options), in a
  // message that names the value given: "--occupied-thresh 2: expected a number in [0, 1]".
  const auto add_threshold = [&](const char *name, double &target) {
    const OptionSpec &row = vasco::option_row(t, name);
    app.add_option(row.flag(), target, flag_help(row))->type_name("P");
  };
  add_threshold("free_thresh", o.free_thresh);
  add_threshold("occupied_thresh", o.occupied_thresh);
  add_row_flag(app, vasco::option_row(t, "negate"), o.negate);
}

// Checks the map_server options: a usage error naming the option, or a
// warning when no output is a map_server pair.
void finish_map_server_options(const CLI::App &app, const MapServerText &raw, Options &opt) {
  const carmen::MapServerOptions &o = opt.map_server;
  opt.map_server = pl::checked_map_server_options(raw.mode, o.free_thresh, o.occupied_thresh, o.negate,
                                                  pl::OptionNaming::Flag);
  std::vector<const OptionSpec *> rows;
  bool given = false;
  for (const std::string &name : pl::map_server_option_names()) {
    rows.push_back(&vasco::option_row(pl::map_output_option_table(), name));
    given = given || app.count(rows.back()->flag()) > 0;
  }
  if (!given) return;
  bool pair = false;
  for (const std::string &f : opt.formats) {
    const carmen::MapFormatEntry *e = carmen::find_map_format_by_name(f);
    pair = pair || (e != nullptr && e->kind == carmen::MapFormatKind::MapServer);
  }
  for (const std::string &out : opt.outputs) {
    const carmen::MapFormatEntry *f = out == cli::kStdio ? nullptr : carmen::find_map_format(out);
    pair = pair || (f != nullptr && f->kind == carmen::MapFormatKind::MapServer);
  }
  if (pair) return;
  std::string pairs = carmen::known_map_extensions(carmen::MapFormatKind::MapServer);  // ".pgm, .png+yaml or .yaml"
  const size_t last = pairs.rfind(", ");
  if (last != std::string::npos) pairs.replace(last, 2, " or ");
  const std::string w = pl::option_names_text(rows, pl::OptionNaming::Flag) + " do nothing without a " + pairs + " output";
  opt.warnings.push_back(w);
  std::fprintf(stderr, "%s: warning: %s\n", opt.tool.c_str(), w.c_str());
}

// "cuda_float, cuda_exact (the mode too), gpu (cuda)": the registry's aliases
// of compiled backends, for --backend's help.
std::string backend_aliases_help() {
  std::string text;
  for (const vasco::BackendInfo &b : vasco::backend_registry()) {
    if (!b.compiled) continue;
    for (const vasco::BackendAlias &a : b.aliases) {
      text += (text.empty() ? "" : ", ") + std::string(a.name) + " (" + b.name;
      if (a.sets_cuda_mode) text += a.cuda_mode == vasco::CudaMode::Exact ? " --cuda-mode exact" : " --cuda-mode float";
      text += ")";
    }
  }
  return text.empty() ? text : "also: " + text + "\n";
}

// The compiled backends, a line each, for --backend's help. auto's line
// gives its one rule as this command line applies it, a single log and a
// batch alike (backend_choice.h: N renders, 1 for a log, 0 for a batch).
std::string backends_help() {
  std::string text;
  for (const vasco::BackendInfo &b : vasco::backend_registry()) {
    if (!b.compiled) continue;
    const std::string summary =
        b.chooses ? "cuda where a GPU is usable and a measured cost model expects it to finish first (in a "
                    "batch its start-up weighs nothing), else cpu_threads"
                  : b.summary;
    text += std::string(b.name) + ": " + summary + "\n";
  }
  return text;
}

void add_backend_options(CLI::App &app, Options &opt) {
  // The registry's names and aliases (one not compiled in says why when
  // run); an unknown one is refused naming the nearest.
  const CLI::Validator known_backend(
      [](std::string &name) -> std::string {
        try {
          vasco::resolve_backend_name(name, nullptr);
          return std::string();
        } catch (const carmen::Error &e) {
          return e.what();
        }
      },
      "");
  // The session's rows (option_schema.h): help, default, bounds and choices.
  const auto row = [](const char *name) -> const OptionSpec & {
    return vasco::option_row(vasco::session_option_table(), name);
  };
  app.add_option("--backend", opt.backend,
                 row("backend").help_with_default() + ", one of:\n" + backends_help() + backend_aliases_help())
      ->type_name("NAME")
      ->check(known_backend);
  const OptionSpec &threads = row("threads");
  app.add_option("--threads", opt.threads, threads.help_with_default())
      ->check(CLI::Range(static_cast<int>(threads.lo), static_cast<int>(threads.hi)));
  app.add_option("--device", opt.device, "the CUDA device of the cuda backend (default 0; a batch: every usable GPU)")->check(CLI::NonNegativeNumber);
  app.add_option("--cuda-mode", opt.cuda_mode, row("cuda_mode").help_with_default())
      ->check(CLI::IsMember(row("cuda_mode").choices));
  app.add_flag("--lenient", opt.lenient, "skip bad log lines (and report them) instead of stopping");
  app.add_flag("--json", opt.json, "print machine-readable statistics on stdout");
  app.add_flag("-q,--quiet", opt.quiet, "no progress and no summary");
}

// What --poses and --add take; checked after parsing (raw holds the text).
struct PoseText {
  std::string format, match, frame, mount, transform;
  std::vector<std::string> adds;
};

// The pose-source options, each from its row (pose_source_options.h), then
// the sessions' --transform and --add.
void add_pose_options(CLI::App &app, Options &opt, PoseText &raw) {
  const vasco::OptionTable &t = pl::pose_source_option_table();
  const auto row = [&t](const char *name) -> const OptionSpec & { return vasco::option_row(t, name); };
  raw.format = row("pose_format").default_text;
  raw.match = row("pose_match").default_text;
  raw.frame = row("pose_frame").default_text;
  add_row_option(app, row("poses"), opt.poses.file, "FILE");
  add_row_option(app, row("pose_format"), raw.format);
  add_row_option(app, row("pose_match"), raw.match);
  add_row_option(app, row("pose_ids"), opt.poses.id_map_file, "FILE");
  add_row_option(app, row("pose_max_gap"), opt.poses.match.max_gap, "SECONDS");
  add_row_option(app, row("pose_tolerance"), opt.poses.match.tolerance, "SECONDS");
  add_row_flag(app, row("skip_unposed"), opt.poses.match.skip_unmatched);
  add_row_option(app, row("pose_frame"), raw.frame);
  add_row_option(app, row("laser_mount"), raw.mount, "X,Y,THETA");
  app.add_option("--transform", raw.transform, "the input into the shared frame of several sessions (default: identity)")
      ->type_name("X,Y,THETA");
  // One value an occurrence: what follows it is OUT (or the next input).
  app.add_option("--add", raw.adds,
                 "a further session mapped into the same grid, its transform after an '@', or '@auto' to find it "
                 "by aligning the session to those before it ('@auto:X,Y,THETA+-R[,RTHETA]': near a guess) "
                 "(repeatable)")
      ->type_name("INPUT[@X,Y,THETA|@auto[:HINT]]")
      ->allow_extra_args(false);
}

// Each vasco_* key with its meaning, vasco's default and its valid values,
// from the one table (params.h): this help is the parameters' reference.
// --resolution first: the written map's cell, as ROS says resolution.
void add_param_options(CLI::App &app, const ToolSpec &spec, std::map<std::string, std::string> &raw) {
  const vasco::MapperParams defaults;
  std::ostringstream def;
  if (spec.default_map_resolution > 0)
    def << spec.default_map_resolution << " unless vasco_resolution is set";
  else
    def << "vasco_resolution x vasco_downsample, " << defaults.map_resolution();
  app.add_option("--resolution", raw["resolution"],
                 "the written map's cell size (m), as ROS's resolution (default " + def.str() +
                     "): sets vasco_resolution = M / vasco_downsample, the downsample kept where given, else "
                     "max(1, round(M / vasco_resolution))")
      ->type_name("M");
  for (const vasco::ParamSpec &p : vasco::param_table()) {
    std::ostringstream help;
    help << p.meaning << " (default " << p.default_value << (p.minus_one_ok ? ", all" : "") << "; " << p.rule << ")";
    app.add_option(std::string("--") + p.key, raw[p.key], help.str())->type_name("VALUE");
  }
}

// "map.gz,png" as the formats of batch outputs (the pipeline's rules).
std::vector<std::string> parse_formats(const std::string &text) {
  std::vector<std::string> formats;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    formats.push_back(text.substr(start, comma - start));
    start = comma + 1;
  }
  return vasco::pipeline::check_map_formats(formats, "--formats '" + carmen::printable(text) + "'");
}

// Batch mode: every positional is an input; the one-input options refused.
void finish_batch_options(const CLI::App &app, const BatchText &raw, Options &opt) {
  const bool batch_only = app.count("--formats") || app.count("--fail-fast") || app.count("--jobs") ||
                          app.count("--devices");
  if (app.count("--split-devices")) {
    if (!opt.out_dir.empty())
      throw Error(ErrorCode::Usage, "--split-devices splits one render: not with --out-dir (--devices spreads a batch)");
    if (app.count("--device")) throw Error(ErrorCode::Usage, "--device and --split-devices: give one of them");
    opt.split_devices = parse_devices(raw.split_devices, "--split-devices");
  }
  if (opt.out_dir.empty()) {
    if (batch_only)
      throw Error(ErrorCode::Usage, "--formats, --fail-fast, --jobs and --devices go with --out-dir DIR");
    if (opt.outputs.empty()) throw Error(ErrorCode::Usage, "no output named: give OUT [OUT...], or --out-dir DIR for a batch");
    return;
  }
  for (const char *one : {"--poses", "--add", "--transform"})
    if (app.count(one)) throw Error(ErrorCode::Usage, std::string(one) + " is for one input: not with --out-dir");
  opt.formats = parse_formats(raw.formats);
  if (app.count("--devices")) {
    if (opt.device_given) throw Error(ErrorCode::Usage, "--device and --devices: give one of them");
    opt.devices = parse_devices(raw.devices, "--devices");
  }
  opt.inputs.push_back(opt.log);
  opt.inputs.insert(opt.inputs.end(), opt.outputs.begin(), opt.outputs.end());
  opt.outputs.clear();
}

void warn_about_idle_options(const CLI::App &app, Options &opt);

// --backend cuda_exact, cuda_float, gpu: the registry's name, and the mode
// an alias sets (a --cuda-mode that says otherwise is a usage error).
void resolve_backend_alias(const CLI::App &app, Options &opt) {
  vasco::BackendOptions o;
  o.cuda_mode = opt.cuda_mode == "exact" ? vasco::CudaMode::Exact : vasco::CudaMode::Float;
  const vasco::CudaMode asked = o.cuda_mode;
  const std::string name = vasco::resolve_backend_name(opt.backend, &o);
  const std::string mode = o.cuda_mode == vasco::CudaMode::Exact ? "exact" : "float";
  if (app.count("--cuda-mode") && o.cuda_mode != asked)
    throw Error(ErrorCode::Usage, "--backend " + opt.backend + " is --cuda-mode " + mode + ": not with --cuda-mode " +
                                      opt.cuda_mode);
  opt.backend = name;
  opt.cuda_mode = mode;
}

// Whether `path` names a ROS bag by its form: a ROS 1 .bag, a ROS 2 .mcap or
// .db3 file, or a ROS 2 bag directory (its metadata.yaml).
bool looks_like_a_bag(const std::string &path) {
  std::string lower = path;
  for (char &c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const char *ext : {".bag", ".mcap", ".db3"}) {
    const std::string e = ext;
    if (lower.size() > e.size() && lower.compare(lower.size() - e.size(), e.size(), e) == 0) return true;
  }
  struct stat st;
  return ::stat((path + "/metadata.yaml").c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

// log2map reads CARMEN logs: a bag given to it is a usage error that names
// the tool that maps bags.
void check_inputs_are_logs(const ToolSpec &spec, const Options &opt) {
  if (spec.read) return;  // a tool with its own reader (bag2map) takes its own inputs
  std::vector<std::string> inputs = opt.out_dir.empty() ? std::vector<std::string>{opt.log} : opt.inputs;
  for (const auto &more : opt.more) inputs.push_back(more.path);
  for (const std::string &in : inputs)
    if (looks_like_a_bag(in))
      throw Error(ErrorCode::Usage, "'" + carmen::printable(in) + "' is a ROS bag, and " + spec.name +
                                        " reads CARMEN logs: map it with bag2map (bag2map " +
                                        carmen::printable(in) + " OUTPUT; the same options)");
}

// Everything checked after parsing that CLI11 cannot: a usage error.
void finish_options(const CLI::App &app, const ToolSpec &spec, const PoseText &raw, const std::string &max_memory,
                    Options &opt) {
  if (app.count("--max-memory") > 0) opt.max_memory_bytes = cli::parse_mebibytes(max_memory, "--max-memory");
  for (const auto &out : opt.outputs)
    if (opt.out_dir.empty() && out != cli::kStdio) carmen::map_format_of(out);  // an unknown extension
  if (opt.out_dir.empty()) {
    const auto to_stdout = std::count(opt.outputs.begin(), opt.outputs.end(), std::string(cli::kStdio));
    if (to_stdout > 1) throw Error(ErrorCode::Usage, "the output '-' (standard output) is named twice: give it once");
    if (to_stdout == 1 && opt.json)
      throw Error(ErrorCode::Usage, "--json and the output '-' both want standard output: write the map to a file");
    opt.log = cli::input_path(opt.log);
  }
  resolve_backend_alias(app, opt);
  opt.poses.format = vasco::pose_file_format_from_name(raw.format);
  opt.poses.match.matching = vasco::pose_matching_from_name(raw.match);
  opt.poses.robot_frame = raw.frame == "robot";
  if (!raw.mount.empty()) {
    opt.poses.mount = parse_pose_triple(raw.mount, "--laser-mount");
    opt.poses.has_mount = true;
    opt.laser_mount_text = raw.mount;
  }
  if (!raw.transform.empty()) opt.transform = parse_pose_triple(raw.transform, "--transform");
  for (const std::string &a : raw.adds) opt.more.push_back(parse_session(a));
  opt.device_given = app.count("--device") > 0;
  // A bag reader takes --laser-mount (a pose topic's mount) and --skip-unposed
  // (scans outside the poses' time span) without --poses too.
  pl::check_pose_options_given(given_rows(app, pl::pose_source_option_table()), static_cast<bool>(spec.read),
                               pl::OptionNaming::Flag);
  warn_about_idle_options(app, opt);
}

// --resolution M: a finite number > 0, and not with --vasco_resolution (two
// answers to one question).
void finish_resolution_option(const CLI::App &app, const std::string &text, Options &opt) {
  if (app.count("--resolution") == 0) return;
  double cell = 0;
  if (!parse_double(text, &cell) || !std::isfinite(cell) || !(cell > 0))
    throw Error(ErrorCode::Usage, "--resolution '" + carmen::printable(text) + "': expected a cell size in metres, a "
                                  "finite number > 0");
  if (app.count("--vasco_resolution"))
    throw Error(ErrorCode::Usage, "--resolution and --vasco_resolution both set the cell size: give one (--resolution: "
                                  "the written map's; --vasco_resolution: the evidence grid's, before vasco_downsample)");
  opt.map_resolution = cell;
}

// Options that change nothing for the chosen backend: a warning each (the
// run goes on), printed at once and carried by --json.
void warn_about_idle_options(const CLI::App &app, Options &opt) {
  const vasco::BackendInfo *b = vasco::find_backend(opt.backend);  // the registry's name (resolve_backend_alias)
  const bool gpus = b == nullptr || b->uses_gpus, threads = b == nullptr || b->uses_threads;
  std::string users;  // "cpu_threads and auto": the backends --threads serves
  for (const vasco::BackendInfo &r : vasco::backend_registry())
    if (r.uses_threads) users += (users.empty() ? "" : " and ") + std::string(r.name);
  if (app.count("--cuda-mode") && !gpus)
    opt.warnings.push_back("--cuda-mode does nothing with --backend " + opt.backend + " (only cuda has modes)");
  for (const char *option : {"--device", "--devices", "--split-devices"})
    if (app.count(option) && !gpus) opt.warnings.push_back(std::string(option) + " does nothing with --backend " + opt.backend);
  if (app.count("--threads") && !threads)
    opt.warnings.push_back("--threads does nothing with --backend " + opt.backend + " (only " + users + " use it)");
  if (app.count("--robot") && opt.param_file.empty())
    opt.warnings.push_back("--robot does nothing without --param-file (it picks a robot section of the ini)");
  for (const std::string &w : opt.warnings) std::fprintf(stderr, "%s: warning: %s\n", opt.tool.c_str(), w.c_str());
}

// "Did you mean --pose-tolerance?" for each unexpected argument that is a
// near miss of an option's name (CLI11 does not suggest); empty otherwise.
std::string option_suggestions(const CLI::App &app, const CLI::Error &e) {
  if (dynamic_cast<const CLI::ExtrasError *>(&e) == nullptr) return std::string();
  std::vector<std::string> names;
  for (const CLI::Option *o : app.get_options())
    for (const std::string &n : o->get_lnames()) names.push_back("--" + n);
  std::string text;
  for (const std::string &arg : app.remaining()) {
    if (arg.size() < 3 || arg.compare(0, 2, "--") != 0) continue;
    const std::string near = vasco::closest_name(arg.substr(0, arg.find('=')), names);
    if (!near.empty()) text += "Did you mean " + near + " (not " + arg.substr(0, arg.find('=')) + ")?\n";
  }
  return text;
}

}  // namespace

vasco::Pose2 parse_pose_triple(const std::string &text, const std::string &option) {
  double v[3];
  size_t start = 0;
  for (int i = 0; i < 3; ++i) {
    const size_t comma = i < 2 ? text.find(',', start) : text.size();
    const bool ok = comma != std::string::npos && parse_double(text.substr(start, comma - start), &v[i]) &&
                    std::isfinite(v[i]) && (i < 2 || text.find(',', start) == std::string::npos);
    if (!ok)
      throw Error(ErrorCode::Usage, option + " '" + text + "': expected X,Y,THETA (three finite numbers: m, m, rad)");
    start = comma + 1;
  }
  return vasco::Pose2{v[0], v[1], v[2]};
}

namespace {

// "X,Y,THETA[±R[,RTHETA]]" ("+-" for "±"): a guess of an "@auto"
// session's transform, searched within R metres in x and y and RTHETA
// radians (AlignHint's defaults where not given).
vasco::AlignHint parse_auto_hint(const std::string &text, const std::string &option) {
  vasco::AlignHint hint;
  size_t pm = text.find("\xC2\xB1");  // "±" in UTF-8
  const size_t pm_len = 2;  // "±" and "+-" alike
  if (pm == std::string::npos) pm = text.find("+-");
  const vasco::Pose2 guess = parse_pose_triple(text.substr(0, pm), option);
  hint.x = guess.x;
  hint.y = guess.y;
  hint.theta = guess.theta;
  if (pm == std::string::npos) return hint;
  const std::string radii = text.substr(pm + pm_len);
  const size_t comma = radii.find(',');
  const auto radius = [&](const std::string &v, double *out) {
    if (!parse_double(v, out) || !std::isfinite(*out) || *out < 0)
      throw Error(ErrorCode::Usage, option + ": expected auto:X,Y,THETA+-R[,RTHETA] (R metres and RTHETA radians: "
                                             "finite, 0 or more), not '" + v + "' after the +-");
  };
  radius(radii.substr(0, comma), &hint.radius_m);
  if (comma != std::string::npos) radius(radii.substr(comma + 1), &hint.radius_rad);
  return hint;
}

}  // namespace

vasco::SessionInput parse_session(const std::string &text) {
  vasco::SessionInput s;
  s.path = text;
  const size_t at = text.rfind('@');
  const std::string after = at == std::string::npos ? std::string() : text.substr(at + 1);
  if (after == "auto" || after.rfind("auto:", 0) == 0) {
    s.path = text.substr(0, at);
    s.auto_transform = true;
    if (after != "auto") s.hint = parse_auto_hint(after.substr(5), "--add " + text);
  } else if (at != std::string::npos && std::count(after.begin(), after.end(), ',') == 2) {
    s.path = text.substr(0, at);
    s.transform = parse_pose_triple(after, "--add " + text);
  }
  if (s.path.empty()) throw Error(ErrorCode::Usage, "--add '" + text + "': no input named");
  return s;
}

int parse_options(int argc, const char *const *argv, const ToolSpec &spec, Options *opt) {
  opt->tool = spec.name;
  opt->max_memory_bytes = vasco::kDefaultMaxMemoryBytes;
  CLI::App app{spec.summary, spec.name};  // named: usage lines say "log2map", not argv[0]
  // Errors name the program, as every message of the tools does.
  const std::string tool = spec.name;
  app.failure_message([tool](const CLI::App *a, const CLI::Error &e) {
    return tool + ": " + e.what() + "\n" + option_suggestions(*a, e) + "Run '" + tool + " --help' for usage.\n";
  });
  app.set_version_flag("--version", [&spec] {
    std::string s = spec.name + " (vasco_gpu) " + vasco::version() + "\nbackends compiled in:";
    for (const auto &b : vasco::compiled_backends()) s += " " + b;
    return s;
  });
  add_input_options(app, spec, *opt);
  std::map<std::string, std::string> extra;
  for (const ExtraOption &e : spec.extra_options) app.add_option("--" + e.name, extra[e.name], e.help)->type_name(e.type_name);
  add_backend_options(app, *opt);
  BatchText raw_batch;
  add_batch_options(app, spec, *opt, raw_batch);
  std::string max_memory;
  app.add_option("--max-memory", max_memory,
                 vasco::option_row(vasco::session_option_table(), "max_memory").help_with_default())
      ->type_name("MiB");
  PoseText raw_poses;
  add_pose_options(app, *opt, raw_poses);
  MapServerText raw_map_server;
  add_map_server_options(app, *opt, raw_map_server);
  std::map<std::string, std::string> raw;
  add_param_options(app, spec, raw);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError &e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  for (const auto &kv : raw)
    if (app.count("--" + kv.first) > 0 && kv.first != "resolution") opt->overrides[kv.first] = kv.second;
  for (const auto &kv : extra)
    if (app.count("--" + kv.first) > 0) opt->extra[kv.first] = kv.second;
  try {
    finish_options(app, spec, raw_poses, max_memory, *opt);
    finish_resolution_option(app, raw["resolution"], *opt);
    finish_batch_options(app, raw_batch, *opt);
    check_inputs_are_logs(spec, *opt);  // a batch's inputs are known from here
    finish_map_server_options(app, raw_map_server, *opt);
  } catch (const carmen::Error &e) {
    std::fprintf(stderr, "%s: %s\n", spec.name.c_str(), carmen::printable(e.what()).c_str());
    return 2;
  }
  return -1;
}

}  // namespace log2map
