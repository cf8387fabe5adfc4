// thread_scaling.h — mapping_bench --thread-scaling: how cpu_threads' map
// phase grows with the cores it is given, beside cpu_double and cpu_float
// (one core each) on the same logs and parameter sets.
//
// Each row is a renderer's reset (every cell unknown again) and apply over
// every scan, as a session renders: the map phase alone, the parse done once
// before and not timed. A warm-up, then N timed runs, the median. The thread
// counts are 1, 2, 4, ... up to the cores there are, and that number (or
// --scaling-threads LIST); a count past the cores is run and marked, since
// threads beyond them only share the same cores.
#ifndef VASCO_BENCH_THREAD_SCALING_H
#define VASCO_BENCH_THREAD_SCALING_H

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "bench_support.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/internal/parallel.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/renderer.h"
#include "vasco_gpu/pipeline/log_scans.h"

namespace bench {

// --thread-scaling and its options.
struct ScalingOptions {
  bool on = false;
  int runs = 5;
  std::string only;          // --dataset: only this one
  std::vector<int> threads;  // --scaling-threads: empty = 1, 2, 4, ... and the core count
};

// "1,2,8" -> {1, 2, 8}; false for anything but positive integers.
inline bool parse_int_list(const std::string &text, std::vector<int> *out) {
  out->clear();
  size_t at = 0;
  while (at <= text.size()) {
    const size_t comma = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, comma - at);
    char *end = nullptr;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end != '\0' || v < 1 || v > 4096) return false;
    out->push_back(static_cast<int>(v));
    at = comma + 1;
  }
  return !out->empty();
}

// 1, 2, 4, ... below `cores`, then `cores` itself.
inline std::vector<int> default_thread_counts(int cores) {
  std::vector<int> t;
  for (int n = 1; n < cores; n *= 2) t.push_back(n);
  t.push_back(std::max(cores, 1));
  return t;
}

// The median map-phase seconds of `backend` with `threads` threads on one log and parameter set.
inline double scaling_map_s(const std::string &backend, int threads, const vasco::ScanBatch &batch,
                            const vasco::MapperParams &p, const vasco::GridGeometry &geo, int runs) {
  vasco::BackendOptions o;
  o.threads = threads;
  std::unique_ptr<vasco::Renderer> r = vasco::make_renderer(backend, o);
  std::vector<double> t;
  for (int i = 0; i <= runs; ++i) {
    const double t0 = now_s();
    r->reset(geo, p);
    r->apply(batch, 0, batch.num_scans(), nullptr);
    if (i > 0) t.push_back(now_s() - t0);  // the first run warms up
  }
  return median(t);
}

inline std::string scaling_ratio(double a, double b, const char *format = "%.2f") {
  char buf[32];
  std::snprintf(buf, sizeof buf, format, a / b);
  return buf;
}

// One log and parameter set: cpu_double and cpu_float on one core, then cpu_threads at each count.
inline void scaling_rows(const Dataset &ds, const ParamSet &ps, const std::vector<int> &counts, int cores,
                         int runs) {
  vasco::LogLoadStats stats;
  const vasco::ScanBatch batch = vasco::load_scans(ds.path, ps.params, carmen::LogReaderOptions{}, &stats);
  const vasco::GridGeometry geo = vasco::size_grid(batch, ps.params);
  std::fprintf(stderr, "%s / %s: %zu scans, grid %d x %d\n", ds.name.c_str(), ps.name.c_str(), batch.num_scans(),
               geo.size_x, geo.size_y);
  const double one_core = scaling_map_s("cpu_double", 1, batch, ps.params, geo, runs);
  const double fast = scaling_map_s("cpu_float", 1, batch, ps.params, geo, runs);
  auto line = [&](const std::string &backend, int threads, double s, const std::string &x1, const std::string &eff) {
    std::printf("| %s | %s | %s | %d%s | %s | %s | %s | %s |\n", ds.name.c_str(), ps.name.c_str(), backend.c_str(),
                threads, threads > cores ? " (past the cores)" : "", ms(s).c_str(),
                scaling_ratio(one_core, s).c_str(), x1.c_str(), eff.c_str());
  };
  line("cpu_double", 1, one_core, "-", "-");
  line("cpu_float", 1, fast, "-", "-");
  double one_thread = 0;  // cpu_threads on one thread, when the counts start there
  for (int n : counts) {
    const double s = scaling_map_s("cpu_threads", n, batch, ps.params, geo, runs);
    if (n == 1) one_thread = s;
    const bool base = one_thread > 0;
    line("cpu_threads", n, s, base ? scaling_ratio(one_thread, s) : "-",
         base ? scaling_ratio(100 * one_thread, s * n, "%.0f %%") : "-");
  }
}

// mapping_bench --thread-scaling.
inline int run_thread_scaling(const ScalingOptions &opt) {
  const int cores = vasco::hardware_threads();
  const std::vector<int> counts = opt.threads.empty() ? default_thread_counts(cores) : opt.threads;
  std::printf("mapping_bench --thread-scaling: map phase alone (renderer reset + apply of every scan), median of %d "
              "runs after a warm-up; %d hardware threads here\n\n",
              opt.runs, cores);
  std::printf("| data | params | backend | threads | map ms | × cpu_double | × 1 thread | efficiency |\n");
  std::printf("|---|---|---|--:|--:|--:|--:|--:|\n");
  for (const Dataset &ds : bench_datasets()) {
    if (!opt.only.empty() && ds.name != opt.only) continue;
    if (access(ds.path.c_str(), R_OK) != 0) {
      std::printf("%s: %s not found, skipped\n", ds.name.c_str(), ds.path.c_str());
      continue;
    }
    for (const ParamSet &ps : bench_param_sets()) scaling_rows(ds, ps, counts, cores, opt.runs);
  }
  std::printf("\n× cpu_double: its one-core time / this row's. × 1 thread: cpu_threads on one thread / this "
              "row's; efficiency: that over the thread count. Every row is the same map (cpu_threads and "
              "cpu_double give CARMEN's bytes; cpu_float the same cells known).\n");
  return 0;
}

}  // namespace bench

#endif  // VASCO_BENCH_THREAD_SCALING_H
