// log2map — turns a CARMEN laser log into a map, as CARMEN's evidence grid
// (vasco/egrid.c) would (DESIGN §3).
//
//   log2map [options] LOG OUT [OUT...]
//
// Outputs by extension: .map / .map.gz (CARMEN), .pgm (+ .yaml, ROS
// map_server), .png. Exit 0 ok, 1 bad input or runtime error, 2 usage error.
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <future>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"
#include "carmen_compat/map_format.h"
#include "carmen_compat/termination_signals.h"
#include "cli_support.h"
#include "vasco_gpu/pipeline/outputs.h"
#include "log2map_app.h"
#include "log2map_batch.h"
#include "log2map_options.h"
#include "log2map_steps.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/backend_choice.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/pipeline/log_input.h"
#include "vasco_gpu/pipeline/pose_source_options.h"
#include "vasco_gpu/map_output.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"
#include "vasco_gpu/version.h"
#if defined(VASCO_HAVE_CUDA)
#include "vasco_gpu/cuda_backend.h"
#endif

namespace log2map {

namespace {

using cli::Clock;
using cli::seconds_since;

// CUDA initialisation costs a few tenths of a second: for --backend cuda
// it starts on another thread while the log is parsed (auto decides after
// reading, by the work: backend_choice.h).
std::future<bool> start_cuda(const Options &opt, const vasco::BackendOptions &bopt) {
  std::future<bool> ready;
#if defined(VASCO_HAVE_CUDA)
  const vasco::BackendInfo *b = vasco::find_backend(opt.backend);
  if (b != nullptr && b->uses_gpus && !b->chooses) {
    ready = carmen::with_termination_signals_blocked([&] {
      return std::async(std::launch::async, [dev = bopt.cuda_device] {
        std::string why;
        return vasco::cuda_usable(dev, &why);
      });
    });
  }
#else
  (void)opt;
  (void)bopt;
#endif
  return ready;
}

void print_summary(const Options &opt, const RunResult &r) {
  const auto &ls = r.input.load.log;
  const vasco::MapStats &ms = r.stats;
  const vasco::GridGeometry &geo = r.input.geo;
  std::fprintf(stderr,
               "%s: %s: %zu scans (of %ld laser messages), %llu beams used, %llu skipped "
               "(>= 50 m, NaN or inf), %llu cell updates\n",
               opt.tool.c_str(), opt.log.c_str(), r.scans, r.input.load.laser_messages,
               (unsigned long long)ms.beams_used, (unsigned long long)ms.beams_skipped,
               (unsigned long long)ms.cell_updates);
  if (!opt.more.empty())
    std::fprintf(stderr, "%s: %zu sessions mapped into one grid\n", opt.tool.c_str(), opt.more.size() + 1);
  // A bag's reader leaves out the scans before the first and after the last
  // pose by default (--skip-unposed: those inside a gap too).
  if (opt.poses.file.empty() && r.input.unposed_skipped > 0)
    std::fprintf(stderr, "%s: %llu scans without a pose left out%s\n", opt.tool.c_str(),
                 (unsigned long long)r.input.unposed_skipped,
                 opt.poses.match.skip_unmatched ? " (--skip-unposed)" : " (before the first or after the last pose)");
  if (!opt.poses.file.empty())
    std::fprintf(stderr, "%s: poses from %s for %llu scans%s\n", opt.tool.c_str(), opt.poses.file.c_str(),
                 (unsigned long long)r.input.posed_from_file,
                 r.input.unposed_skipped ? (", " + std::to_string(r.input.unposed_skipped) +
                                            " scans without a pose left out (--skip-unposed)").c_str()
                                         : "");
  if (ls.nan_ranges + ls.inf_ranges + ls.negative_ranges)
    std::fprintf(stderr, "%s: odd ranges kept as data: %llu NaN, %llu inf, %llu negative\n", opt.tool.c_str(),
                 (unsigned long long)ls.nan_ranges, (unsigned long long)ls.inf_ranges,
                 (unsigned long long)ls.negative_ranges);
  if (ls.total_bad_lines())
    std::fprintf(stderr, "%s: lenient: skipped %llu bad lines\n%s\n", opt.tool.c_str(),
                 (unsigned long long)ls.total_bad_lines(), ls.summary().c_str());
  std::fprintf(stderr, "%s: grid %d x %d at %g m -> map %d x %d at %g m (%llu known cells)\n", opt.tool.c_str(), geo.size_x,
               geo.size_y, geo.resolution, r.map.size_x, r.map.size_y, r.map.resolution,
               (unsigned long long)r.known);
  std::fprintf(stderr,
               "%s: backend %s; parse %.3f s, prep %.3f s, upload %.3f s, map %.3f s, "
               "download %.3f s, finish %.3f s, write %.3f s, total %.3f s\n",
               opt.tool.c_str(),
               r.backend.c_str(), r.parse_s, ms.prep_s, ms.upload_s, ms.map_s, ms.download_s, r.finish_s,
               r.write_s, r.total_s);
}

// A number of the JSON at full precision (a transform given back maps the
// same bytes), null where not finite.
std::string json_exact(double v) {
  if (!std::isfinite(v)) return "null";
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

std::string json_triple(double x, double y, double theta) {
  return "[" + json_exact(x) + "," + json_exact(y) + "," + json_exact(theta) + "]";
}

// "added_sessions": each --add's transform as mapped, and for an "@auto"
// one what the alignment found (the scores to judge it by).
std::string added_sessions_json(const std::vector<vasco::AddedSession> &added) {
  std::string j = "[";
  for (size_t i = 0; i < added.size(); ++i) {
    const vasco::AddedSession &a = added[i];
    const vasco::AlignResult &r = a.result;
    j += std::string(i ? "," : "") + "{\"input\":" + cli::json_string(a.input) +
         ",\"transform\":" + json_triple(a.transform.x, a.transform.y, a.transform.theta) +
         ",\"aligned\":" + (a.aligned ? "\"auto\"" : "\"given\"");
    if (!a.aligned) {
      j += ",\"score\":null,\"second_score\":null,\"second_transform\":null,\"overlap\":null}";
      continue;
    }
    j += ",\"score\":" + json_exact(r.best.score) + ",\"second_score\":" +
         (r.has_second ? json_exact(r.second.score) : "null") + ",\"second_transform\":" +
         (r.has_second ? json_triple(r.second.x, r.second.y, r.second.theta) : "null") +
         ",\"overlap\":" + json_exact(r.overlap) + ",\"seconds\":" + json_exact(a.seconds) + "}";
  }
  return j + "]";
}

void print_json(const Options &opt, const RunResult &r) {
  const auto &ls = r.input.load.log;
  const vasco::MapStats &ms = r.stats;
  const vasco::GridGeometry &geo = r.input.geo;
  std::ostringstream j;
  j.precision(9);
  j << "{\"log\":" << cli::json_string(opt.log) << ",\"backend\":" << cli::json_string(r.backend)
    << ",\"scans\":" << r.scans << ",\"laser_messages\":" << r.input.load.laser_messages
    << ",\"beams_used\":" << ms.beams_used << ",\"beams_skipped\":" << ms.beams_skipped
    << ",\"cell_updates\":" << ms.cell_updates << ",\"nan_ranges\":" << ls.nan_ranges
    << ",\"inf_ranges\":" << ls.inf_ranges << ",\"negative_ranges\":" << ls.negative_ranges
    << ",\"bad_lines\":" << ls.total_bad_lines() << ",\"sessions\":" << opt.more.size() + 1
    << ",\"added_sessions\":" << added_sessions_json(r.input.added_sessions)
    << ",\"posed_from_file\":" << r.input.posed_from_file << ",\"unposed_skipped\":" << r.input.unposed_skipped << ",\"grid\":[" << geo.size_x << "," << geo.size_y
    << "],\"map\":[" << r.map.size_x << "," << r.map.size_y << "],\"map_resolution\":" << r.map.resolution
    << ",\"known_cells\":" << r.known << ",\"origin\":[" << r.origin.x << "," << r.origin.y << "]"
    << ",\"seconds\":{\"parse\":" << r.parse_s << ",\"prep\":" << ms.prep_s << ",\"upload\":" << ms.upload_s
    << ",\"map\":" << ms.map_s << ",\"map_total\":" << r.map_total_s << ",\"download\":" << ms.download_s
    << ",\"finish\":" << r.finish_s << ",\"write\":" << r.write_s << ",\"total\":" << r.total_s
    << "},\"outputs\":[";
  for (size_t i = 0; i < opt.outputs.size(); ++i) j << (i ? "," : "") << cli::json_string(opt.outputs[i]);
  j << "],\"parameters\":{";
  bool first = true;
  for (const vasco::ParamSpec &p : vasco::param_table()) {
    j << (first ? "" : ",") << cli::json_string(p.key) << ":" << p.get(r.input.params);
    first = false;
  }
  j << "},\"warnings\":[";
  first = true;
  for (const std::string &w : opt.warnings) {
    j << (first ? "" : ",") << cli::json_string(w);
    first = false;
  }
  for (const std::string &w : r.input.warnings) {
    j << (first ? "" : ",") << cli::json_string(w);
    first = false;
  }
  j << "]}\n";
  std::fputs(j.str().c_str(), stdout);
}

// --json after a failure: still one object on stdout, the error's file and
// line (where it has them), message and kind, so that a script reading the
// JSON learns why there is no map.
void print_json_error(const std::exception &e) {
  std::ostringstream j;
  j << "{\"error\":{";
  const auto *file_error = dynamic_cast<const carmen::FileError *>(&e);
  if (file_error != nullptr) {
    j << "\"file\":" << cli::json_string(file_error->file()) << ",";
    if (file_error->line() > 0) j << "\"line\":" << file_error->line() << ",";
    j << "\"message\":" << cli::json_string(file_error->message());
  } else {
    j << "\"message\":" << cli::json_string(e.what());
  }
  const auto *error = dynamic_cast<const carmen::Error *>(&e);
  j << ",\"kind\":" << cli::json_string(error != nullptr ? carmen::error_code_name(error->code()) : "internal")
    << "}}\n";
  std::fputs(j.str().c_str(), stdout);
  std::fflush(stdout);
}

// Everything refused before the log is read: outputs that cannot or must
// not be written, and a --json with nowhere to go.
void check_before_work(const Options &opt) {
  std::vector<std::string> inputs = {opt.log, opt.param_file, opt.poses.file, opt.poses.id_map_file};
  for (const vasco::SessionInput &more : opt.more) inputs.push_back(more.path);
  vasco::pipeline::check_outputs(inputs, files_written(opt.outputs));
  if (opt.json) cli::check_stdout_writable("--json");
  for (const std::string &out : opt.outputs)
    if (out == cli::kStdio) cli::check_stdout_writable("the output '-'");
}

// --backend auto for one input: the backend expected to finish first, and
// a note saying which and why.
std::string chosen_backend(const Options &opt, const vasco::BackendOptions &bopt, const vasco::LogInput &in) {
  const vasco::BackendInfo *b = vasco::find_backend(opt.backend);
  if (b == nullptr || !b->chooses) return opt.backend;
  const vasco::AutoChoice c = vasco::choose_auto(&in.batch, in.params, bopt);
  if (!opt.quiet)
    std::fprintf(stderr, "%s: --backend auto: %s: using %s\n", opt.tool.c_str(), c.why.c_str(), c.backend.c_str());
  return c.backend;
}

// The mapping session in the PROTOCOL frame, fed every scan at once.
void make_map(const Options &opt, const vasco::BackendOptions &bopt, RunResult &r) {
  vasco::Mapper mapper(r.input.params, chosen_backend(opt, bopt, r.input), bopt);
  map_input(mapper, opt.log, r);
}

// The statistics come after the maps are in place: a failure to print them
// says so, so that nobody takes the exit status for a missing map.
void print_report(const Options &opt, const RunResult &r) {
  for (const auto &w : r.input.warnings)
    std::fprintf(stderr, "%s: warning: %s\n", opt.tool.c_str(), carmen::printable(w).c_str());
  if (!opt.quiet) print_summary(opt, r);
  if (opt.json) print_json(opt, r);
  if (std::fflush(stdout) != 0 || std::ferror(stdout))
    throw carmen::Error(carmen::ErrorCode::Io, std::string("the maps were written, but the statistics could not be "
                                                           "written to standard output: ") + std::strerror(errno));
}

int run(const Options &opt, const ToolSpec &spec) {
  const auto t_start = Clock::now();
  carmen::remove_temporaries_on_signals();
  check_before_work(opt);
  const vasco::BackendOptions bopt = backend_options(opt);
  std::future<bool> gpu_ready = start_cuda(opt, bopt);

  RunResult r;
  auto t = Clock::now();
  {
    ProgressBar bar(spec.read ? "read" : "parse", progress_wanted(opt));
    r.input = read_input(opt, opt.log, spec, &bar);
  }
  r.parse_s = seconds_since(t);
  {
    PhaseTicker ticker("start the GPU", progress_wanted(opt) && gpu_ready.valid());
    if (gpu_ready.valid()) gpu_ready.wait();
  }
  {
    PhaseTicker ticker("map (" + opt.backend + ")",
                       progress_wanted(opt));
    make_map(opt, bopt, r);
  }
  t = Clock::now();
  {
    PhaseTicker ticker("write", progress_wanted(opt));
    write_outputs(opt, opt.log, opt.outputs, r);
  }
  r.write_s = seconds_since(t);
  r.total_s = seconds_since(t_start);
  print_report(opt, r);
  return 0;
}

}  // namespace

int run_tool(int argc, const char *const *argv, const ToolSpec &spec) {
  Options opt;
  const int parsed = parse_options(argc, argv, spec, &opt);
  if (parsed >= 0) return parsed;
  const char *tool = spec.name.c_str();
  try {
    return opt.out_dir.empty() ? run(opt, spec) : run_batch(opt, spec);
  } catch (const std::bad_alloc &) {
    std::fprintf(stderr, "%s: out of memory\n", tool);
    if (opt.json) print_json_error(carmen::Error(carmen::ErrorCode::OutOfMemory, "out of memory"));
  } catch (const std::exception &e) {
    std::fprintf(stderr, "%s: %s\n", tool, carmen::printable(e.what()).c_str());
    if (opt.json) print_json_error(e);
    return cli::exit_status(e);
  }
  return 1;
}

ToolSpec log2map_spec() {
  ToolSpec spec;
  spec.name = "log2map";
  spec.summary =
      "log2map: builds a CARMEN evidence-grid map (vasco/egrid.c) from a laser log.\n"
      "Outputs by extension: " + carmen::known_map_extensions() + ".";
  spec.input_name = "LOG";
  spec.input_help = "CARMEN log (" + vasco::pipeline::carmen_log_extensions_text(", ") + ", or gzipped .gz)";
  return spec;
}

}  // namespace log2map
