#include "log2map_steps.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <iterator>
#include <map>
#include <memory>
#include <sstream>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"
#include "carmen_compat/termination_signals.h"
#include "cli_support.h"
#include "vasco_gpu/pipeline/mapped.h"
#include "vasco_gpu/pipeline/outputs.h"
#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/map_output.h"
#include "vasco_gpu/version.h"

namespace log2map {

void ProgressBar::update(uint64_t done_units, uint64_t total) {
  if (!enabled_ || total == 0) return;
  const int pct = static_cast<int>(100.0 * double(done_units) / double(total));
  if (pct == last_) return;
  last_ = pct;
  const int width = 40, filled = std::min(width, pct * width / 100);
  std::fprintf(stderr, "\r%-8s [%s%s] %3d%%", label_, std::string(filled, '#').c_str(),
               std::string(width - filled, ' ').c_str(), std::min(pct, 100));
  std::fflush(stderr);
  shown_ = true;
}

void ProgressBar::done() {
  if (shown_) std::fprintf(stderr, "\r%*s\r", 60, "");
  shown_ = false;
  last_ = -1;
}

PhaseTicker::PhaseTicker(std::string label, bool enabled) : label_(std::move(label)) {
  if (enabled) thread_ = carmen::start_thread([this] { tick(); });
}

PhaseTicker::~PhaseTicker() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  stop_cv_.notify_one();
  thread_.join();
}

void PhaseTicker::tick() {
  const auto start = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  if (stop_cv_.wait_for(lock, std::chrono::milliseconds(500), [this] { return stop_; })) return;
  do {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "\r%-24s %6.1f s", label_.c_str(), s);
    std::fflush(stderr);
  } while (!stop_cv_.wait_for(lock, std::chrono::milliseconds(200), [this] { return stop_; }));
  std::fprintf(stderr, "\r%*s\r", 60, "");
  std::fflush(stderr);
}

bool progress_wanted(const Options &opt) { return !opt.quiet && isatty(STDERR_FILENO); }

std::string basename_of(const std::string &path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::vector<std::string> files_written(const std::vector<std::string> &outputs) {
  std::vector<std::string> named;  // standard output ('-') has nothing to replace
  std::copy_if(outputs.begin(), outputs.end(), std::back_inserter(named),
               [](const std::string &out) { return out != cli::kStdio; });
  return vasco::pipeline::output_files(named);
}

vasco::BackendOptions backend_options(const Options &opt) {
  vasco::BackendOptions bopt;
  bopt.cuda_mode = opt.cuda_mode == "exact" ? vasco::CudaMode::Exact : vasco::CudaMode::Float;
  bopt.threads = opt.threads;
  bopt.cuda_device = opt.split_devices.empty() ? opt.device : opt.split_devices[0];
  bopt.split_devices = opt.split_devices;
  bopt.max_memory_bytes = opt.max_memory_bytes;
  bopt.budget_hint = "--max-memory MiB";
  // auto's renders (backend_choice.h): one input is mapped once; a batch's
  // mapper maps every input, its start-up paid once (a workload without end).
  bopt.expected_renders = opt.out_dir.empty() ? 1 : 0;
  return bopt;
}

namespace {

vasco::LogInput read_input_once(const Options &opt, const std::string &log, const ToolSpec &spec, ProgressBar *bar);

// The line an "@auto" session's alignment prints (the transform at full
// precision: given back with --add INPUT@X,Y,THETA it maps the same bytes).
void print_aligned(const Options &opt, const vasco::AddedSession &a) {
  const vasco::AlignResult &r = a.result;
  std::fprintf(stderr, "%s: %s: aligned (@auto): transform %.17g,%.17g,%.17g score %.3f", opt.tool.c_str(),
               carmen::printable(a.input).c_str(), a.transform.x, a.transform.y, a.transform.theta, r.best.score);
  if (r.has_second) std::fprintf(stderr, " (second %.3f)", r.second.score);
  std::fprintf(stderr, ", overlap %.2f, %.2f s\n", r.overlap, a.seconds);
}

}  // namespace

// --lenient skips bad lines, and only them: a file that cannot be read on (a
// truncated or corrupt .gz, a read error) still stops the run, since the map
// would silently lack the rest of the log. The message says so.
vasco::LogInput read_input(const Options &opt, const std::string &log, const ToolSpec &spec, ProgressBar *bar) {
  try {
    return read_input_once(opt, log, spec, bar);
  } catch (const carmen::FileError &e) {
    // A failure at a line of a lenient read is the file's, not a line's.
    if (!opt.lenient || e.line() <= 0) throw;
    throw carmen::FileError(e.file(), e.line(),
                            e.message() + " (--lenient skips bad lines, not a damaged file: the run stops rather "
                                          "than map part of the log)",
                            e.code());
  }
}

namespace {

vasco::LogInput read_input_once(const Options &opt, const std::string &log, const ToolSpec &spec, ProgressBar *bar) {
  vasco::LogInputOptions in;
  in.log = log;
  in.transform = opt.transform;
  in.poses = opt.poses;
  in.param_file = opt.param_file;
  in.robot = opt.robot;
  in.overrides = opt.overrides;
  in.map_resolution = opt.map_resolution;
  in.default_map_resolution = spec.default_map_resolution;
  in.lenient = opt.lenient;
  in.memory_budget = opt.max_memory_bytes;  // the scans alone may not pass what the map may use
  in.budget_option = "--max-memory";
  if (bar != nullptr) in.progress = [bar](uint64_t done, uint64_t total) { bar->update(done, total); };
  in.more_logs = opt.more;
  in.align.threads = opt.threads;
  if (!opt.quiet)
    in.align.aligned = [&opt, bar](const vasco::AddedSession &a) {
      if (bar != nullptr) bar->done();
      print_aligned(opt, a);
    };
  if (!spec.read) return vasco::load_log_input(in);
  // Another kind of input: the tool's reader makes the scans, the sessions
  // are appended here, the rest is a log's. The reader learns of --poses
  // (its inputs' poses are then not needed), --laser-mount (the mount of a
  // pose topic's robot) and --skip-unposed too.
  std::map<std::string, std::string> values = opt.extra;
  if (!opt.poses.file.empty()) values["poses"] = opt.poses.file;
  if (opt.poses.has_mount) values["laser-mount"] = opt.laser_mount_text;
  if (opt.poses.match.skip_unmatched) values["skip-unposed"] = "1";
  const auto no_progress = [](uint64_t, uint64_t) {};
  const std::function<void(uint64_t, uint64_t)> progress = in.progress ? in.progress : no_progress;
  vasco::StampedScans scans = spec.read(log, values, progress);
  std::vector<vasco::StampedScans> more_scans;
  for (const vasco::SessionInput &more : opt.more) {
    if (bar != nullptr) bar->done();
    more_scans.push_back(spec.read(more.path, values, progress));
  }
  if (bar != nullptr) bar->done();
  return vasco::log_input_from_sessions(std::move(scans), std::move(more_scans), in);
}

// A map cell so large that CARMEN's finish, which keeps only whole blocks
// of downsample x downsample grid cells counted from the grid's corner,
// keeps none of the cells the beams updated: the parameters' fault, not the
// log's (a usage error naming the options and the map it would give).
void check_blocks_keep_a_cell(const RunResult &r) {
  const int ds = r.input.params.downsample;
  if (r.known > 0 || r.stats.cell_updates == 0 || ds <= 1) return;
  const vasco::GridGeometry &g = r.input.geo;
  std::ostringstream m;
  m << "a map cell of " << r.input.params.map_resolution() << " m (vasco_downsample " << ds << " x vasco_resolution "
    << r.input.params.resolution << " m) leaves no mapped cell: the finish keeps whole blocks of " << ds << " x " << ds
    << " grid cells from the corner of the " << g.size_x << " x " << g.size_y << "-cell grid, a map of "
    << g.size_x / ds << " x " << g.size_y / ds << " cells, and none of them holds a cell a beam updated; "
    << "give a smaller --resolution or --vasco_downsample";
  throw carmen::Error(carmen::ErrorCode::Usage, m.str());
}
}  // namespace

void map_input(vasco::Mapper &mapper, const std::string &log, RunResult &r) {
  using cli::Clock;
  mapper.start_over(r.input.params);
  r.backend = mapper.backend_name();
  r.scans = r.input.batch.num_scans();
  auto t = Clock::now();
  try {
    mapper.insert(std::move(r.input.batch));
  } catch (const carmen::Error &e) {
    // Over the memory budget (the host's, or a GPU's free memory): the log's
    // poses decide the grid, so name it and the scans that stretch it (a bad
    // pose far away reads as a grid no budget holds).
    if (e.code() == carmen::ErrorCode::OutOfMemory) {
      vasco::PoseExtent extent;
      extent.add(r.input.batch, 0, r.input.batch.num_scans());  // given back by the failed insert
      const std::string span = extent.scans > 0 ? "; " + vasco::pose_span_text(extent, r.input.batch) : "";
      throw carmen::FileError(log, e.what() + span, e.code());
    }
    throw;
  }
  r.stats = mapper.last_stats();
  r.map_total_s = cli::seconds_since(t);
  t = Clock::now();
  r.map = mapper.finish();
  r.finish_s = cli::seconds_since(t);
  r.known = vasco::pipeline::known_cells(r.map.cells);
  check_blocks_keep_a_cell(r);
  vasco::pipeline::check_mapped(r.map.cells, mapper.scans(), log);
  r.origin = vasco::world_origin(r.map, r.input.geo);
}

void write_outputs(const Options &opt, const std::string &log, const std::vector<std::string> &outputs,
                   const RunResult &r) {
  carmen::MapToWrite map = vasco::map_to_write(r.map, r.input.geo);
  map.author = opt.tool;
  map.source = basename_of(log);
  map.description = "vasco_gpu " + std::string(vasco::version()) + " " + r.backend;
  map.time = static_cast<int64_t>(std::time(nullptr));
  map.pgm_mode = opt.map_server.mode;  // the map_server outputs' settings
  map.free_thresh = opt.map_server.free_thresh;
  map.occupied_thresh = opt.map_server.occupied_thresh;
  map.negate = opt.map_server.negate;
  // The output "-" (a CARMEN map) before the transaction, so that the
  // transaction, destroyed first, takes its temporary out of the directory
  // before the directory goes.
  std::unique_ptr<cli::StdoutFile> to_stdout;
  carmen::OutputTransaction tx;
  for (const std::string &out : outputs) {
    if (out == cli::kStdio) {
      to_stdout = std::make_unique<cli::StdoutFile>(".map");
      carmen::write_map(tx, to_stdout->path(), map);
    } else {
      carmen::write_map(tx, out, map);
    }
  }
  tx.commit();
  if (to_stdout) to_stdout->send();
}

}  // namespace log2map
