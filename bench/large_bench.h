// large_bench.h — mapping_bench --large: every backend on a synthetic
// large-site log (large_site.h) at one or more resolutions, through a
// mapping session as log2map maps a log (one insert of every scan, finish),
// with the grid's size, the time, and the memory each backend took.
//
// Memory. Host: the peak resident set of the run (VmHWM after
// /proc/self/clear_refs reset it, minus the resident set before), beside the
// session's own estimate (Mapper::memory_need, what the budget is checked
// against). Device: the renderer's estimate (RendererTraits::
// device_bytes_per_cell times the cells) and the free memory the session
// took (cudaMemGetInfo before it and after its finish; the renderer keeps its
// buffers while it lives). Where the default host budget (2 GiB) is too
// small the run raises it to the need and says so; a run whose need passes
// the memory this machine has available is skipped and says so.
#ifndef VASCO_BENCH_LARGE_BENCH_H
#define VASCO_BENCH_LARGE_BENCH_H

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_support.h"
#include "large_site.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/params.h"
#if defined(VASCO_HAVE_CUDA)
#include "vasco_gpu/cuda_backend.h"
#endif

namespace bench {

// --large and its options.
struct LargeOptions {
  bool on = false;
  LargeSite site;
  std::vector<double> resolutions = {0.1, 0.05, 0.025};  // vasco's default last
  std::vector<std::string> backends;                     // empty: every one available
  int threads = 0;
};

// "0.1,0.05" -> {0.1, 0.05}; false for anything else.
inline bool parse_number_list(const std::string &text, std::vector<double> *out) {
  out->clear();
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    char *end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !(v > 0)) return false;
    out->push_back(v);
  }
  return !out->empty();
}

inline std::vector<std::string> split_names(const std::string &text) {
  std::vector<std::string> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

// A backend of the large bench: the session's backend name and CUDA mode.
struct LargeBackend {
  std::string label;
  std::string factory;
  vasco::CudaMode mode = vasco::CudaMode::Float;
  bool gpu = false;
  int split = 0;  // 2: each render split in two bands (GPUs 0 and 1, or twice GPU 0)
};

inline const std::vector<LargeBackend> &large_backends() {
  static const std::vector<LargeBackend> all = {
      {"cpu_double", "cpu_double", vasco::CudaMode::Float, false},
      {"cpu_threads", "cpu_threads", vasco::CudaMode::Float, false},
      {"cpu_float", "cpu_float", vasco::CudaMode::Float, false},
      {"cuda_float", "cuda", vasco::CudaMode::Float, true},
      {"cuda_exact", "cuda", vasco::CudaMode::Exact, true},
      {"cuda_float/2", "cuda", vasco::CudaMode::Float, true, 2},
      {"cuda_exact/2", "cuda", vasco::CudaMode::Exact, true, 2}};
  return all;
}

// A kB figure of /proc/self/status ("VmRSS", "VmHWM") or /proc/meminfo
// ("MemAvailable"), in bytes; -1 when it cannot be read.
inline double proc_kib(const char *file, const std::string &key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (line.compare(0, key.size() + 1, key + ":") == 0) return std::atof(line.c_str() + key.size() + 1) * 1024.0;
  return -1;
}

// Resets the peak resident set (VmHWM) to the current one.
inline bool reset_peak_rss() {
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
  f.flush();
  return static_cast<bool>(f);
}

inline std::string gib(double bytes) {
  if (bytes < 0) return "-";
  char b[32];
  std::snprintf(b, sizeof b, bytes < 10.0 * (1 << 30) ? "%.2f GiB" : "%.1f GiB", bytes / (1 << 30));
  return b;
}

// Prints "label: N s" to stderr every 10 s while it lives (a long insert).
class Ticker {
 public:
  explicit Ticker(std::string label) : label_(std::move(label)), t0_(std::chrono::steady_clock::now()) {
    thread_ = std::thread([this] {
      std::unique_lock<std::mutex> lock(mutex_);
      while (!cv_.wait_for(lock, std::chrono::seconds(10), [this] { return done_; }))
        std::fprintf(stderr, "      ... %s: %.0f s\n", label_.c_str(),
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count());
    });
  }
  ~Ticker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }

 private:
  std::string label_;
  std::chrono::steady_clock::time_point t0_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;
};

struct LargeRow {
  double resolution = 0;
  std::string backend;
  int size_x = 0, size_y = 0;
  uint64_t cells = 0, scans = 0, beams = 0, updates = 0;
  double map_s = -1, finish_s = -1;
  double host_peak = -1, host_need = -1, device_est = -1, device_used = -1;
  std::string note;
};

// Free device memory now, or -1 (no CUDA build, or CUDA cannot say).
inline double device_free(int device) {
#if defined(VASCO_HAVE_CUDA)
  size_t f = 0, t = 0;
  if (vasco::cuda_memory_info(device, &f, &t)) return static_cast<double>(f);
#else
  (void)device;
#endif
  return -1;
}

// One backend on the large site's scans at one resolution.
inline LargeRow run_large(const LargeBackend &b, const vasco::ScanBatch &scans, const vasco::MapperParams &params,
                          int threads) {
  LargeRow row;
  row.resolution = params.resolution;
  row.backend = b.label;
  row.scans = scans.num_scans();
  const vasco::GridGeometry geo = vasco::size_grid(scans, params);
  row.size_x = geo.size_x;
  row.size_y = geo.size_y;
  row.cells = geo.num_cells();
  try {
    vasco::BackendOptions o;
    o.cuda_mode = b.mode;
    for (int i = 0; i < b.split; ++i) o.split_devices.push_back(i % std::max(vasco::cuda_device_count(), 1));
    o.threads = threads;
    vasco::Mapper m(params, b.factory, o);
    row.host_need = m.memory_need(geo, scans.num_beams());
    // The renderer's bytes a cell and the finish's on the device: block means
    // and the crop, 4 bytes a block each (8 / ds^2 a cell).
    const double ds = static_cast<double>(params.downsample);
    if (b.gpu)
      row.device_est = (m.backend_traits().device_bytes_per_cell + 8.0 / (ds * ds)) * static_cast<double>(row.cells);
    const double available = proc_kib("/proc/meminfo", "MemAvailable");
    if (available > 0 && row.host_need > 0.9 * available) {
      row.note = "skipped: needs " + gib(row.host_need) + " of host memory, " + gib(available) + " available";
      return row;
    }
    if (row.host_need > static_cast<double>(vasco::kDefaultMaxMemoryBytes)) {
      const uint64_t budget = static_cast<uint64_t>(std::ceil(row.host_need / (1 << 20))) << 20;
      m.set_max_memory_bytes(budget);
      row.note = "budget raised to " + std::to_string(budget >> 20) + " MiB";
    }
    const double free_before = b.gpu ? device_free(o.cuda_device) : -1;
    const double rss0 = proc_kib("/proc/self/status", "VmRSS");
    const bool peak_reset = reset_peak_rss();
    std::fprintf(stderr, "    %s: host need %s%s ...\n", b.label.c_str(), gib(row.host_need).c_str(),
                 b.gpu ? (", device " + gib(row.device_est)).c_str() : "");
    const double t0 = now_s();
    {
      Ticker tick(b.label + " insert");
      m.insert(scans);
    }
    const double t1 = now_s();
    const vasco::FinishedMap fin = m.finish();
    const double t2 = now_s();
    row.map_s = t1 - t0;
    row.finish_s = t2 - t1;
    row.beams = m.last_stats().beams_used;
    row.updates = m.last_stats().cell_updates;
    const double hwm = proc_kib("/proc/self/status", peak_reset ? "VmHWM" : "VmPeak");
    if (hwm > 0 && rss0 > 0) row.host_peak = hwm - rss0;
    if (!peak_reset) row.note += std::string(row.note.empty() ? "" : "; ") + "host peak: VmPeak (clear_refs refused)";
    if (b.gpu && free_before >= 0) row.device_used = free_before - device_free(o.cuda_device);
    std::fprintf(stderr, "    %s: %.2f s map, %.2f s finish, finished map %d x %d\n", b.label.c_str(), row.map_s,
                 row.finish_s, fin.size_x, fin.size_y);
  } catch (const vasco::Error &e) {
    std::string what = e.what();
    if (what.size() > 160) what = what.substr(0, 157) + "...";
    row.note = std::string(vasco::error_code_name(e.code())) + ": " + what;
  } catch (const std::bad_alloc &) {
    row.note = "out of memory (std::bad_alloc)";
  }
  return row;
}

inline std::string cells_text(uint64_t n) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", static_cast<double>(n));
  return b;
}

inline void print_large_table(const LargeOptions &opt, const std::vector<LargeRow> &rows) {
  const LargeSite &s = opt.site;
  std::printf("\nLarge site: a %.0f m x %.0f m square loop of %.1f m corridor, the robot starting in a corner,\n"
              "%zu scans of %d beams over 180 deg (laser range %.0f m), vasco's defaults but the resolution;\n"
              "map = the insert (grid cleared and every scan applied; GPU rows: wall time, upload and\n"
              "kernels), finish = CARMEN's finish at vasco_downsample 4. Host peak: resident set of the run\n"
              "(VmHWM); need: Mapper::memory_need, what the host budget is checked against. Device: the\n"
              "renderer's bytes a cell and the finish's, times the cells / free memory the session took\n"
              "(cudaMemGetInfo; per-beam scratch included). Estimates are upper bounds: the finish crops\n"
              "to the known cells, and cpu_float's sums cover only the cells the scans reach.\n",
              s.side, s.side, s.corridor, s.scans, s.beams, s.laser_max);
  const int width = 150;
  std::printf("%s\n", std::string(width, '-').c_str());
  std::printf("%-6s %-11s %-15s %8s %6s %8s %10s %8s %8s %10s %10s %21s  %s\n", "res", "backend", "grid", "cells",
              "scans", "beams", "updates", "map s", "finish s", "host peak", "host need", "device est / used",
              "note");
  std::printf("%s\n", std::string(width, '-').c_str());
  for (const LargeRow &r : rows) {
    const std::string grid = std::to_string(r.size_x) + " x " + std::to_string(r.size_y);
    char map_s[16] = "-", fin_s[16] = "-";
    if (r.map_s >= 0) std::snprintf(map_s, sizeof map_s, "%.2f", r.map_s);
    if (r.finish_s >= 0) std::snprintf(fin_s, sizeof fin_s, "%.2f", r.finish_s);
    const std::string device = r.device_est < 0 ? "-" : gib(r.device_est) + " / " + gib(r.device_used);
    std::printf("%-6.3g %-11s %-15s %8s %6llu %8llu %10llu %8s %8s %10s %10s %21s  %s\n", r.resolution,
                r.backend.c_str(), grid.c_str(), cells_text(r.cells).c_str(), (unsigned long long)r.scans,
                (unsigned long long)r.beams, (unsigned long long)r.updates, map_s, fin_s, gib(r.host_peak).c_str(),
                gib(r.host_need).c_str(), device.c_str(), r.note.c_str());
  }
  std::printf("%s\n", std::string(width, '-').c_str());
}

// The whole --large run: the scans once, then every resolution and backend.
inline int run_large_bench(const LargeOptions &opt) {
  std::vector<LargeBackend> chosen;
  const bool gpu = vasco::gpu_usable(0);
  if (opt.backends.empty()) {
    for (const LargeBackend &b : large_backends())  // split rows by default where there are two GPUs
      if ((!b.gpu || gpu) && (b.split == 0 || vasco::cuda_device_count() >= 2)) chosen.push_back(b);
  } else {
    for (const std::string &name : opt.backends) {
      const auto it = std::find_if(large_backends().begin(), large_backends().end(),
                                   [&](const LargeBackend &b) { return b.label == name; });
      if (it == large_backends().end()) {
        std::fprintf(stderr, "mapping_bench: --large-backends: unknown backend '%s' (known: cpu_double, "
                             "cpu_threads, cpu_float, cuda_float, cuda_exact, cuda_float/2, cuda_exact/2)\n", name.c_str());
        return 2;
      }
      chosen.push_back(*it);
    }
  }
  std::printf("vasco_gpu mapping_bench --large: GPU %s\n", gpu ? "usable" : "none (CPU rows only unless asked)");
  std::fflush(stdout);
  const double t0 = now_s();
  const vasco::ScanBatch scans = large_site_scans(opt.site);
  std::fprintf(stderr, "large site: %zu scans, %zu beams, made in %.2f s\n", scans.num_scans(), scans.num_beams(),
               now_s() - t0);
  std::vector<LargeRow> rows;
  for (double res : opt.resolutions) {
    vasco::MapperParams p;
    p.resolution = res;
    const vasco::GridGeometry geo = vasco::size_grid(scans, p);
    std::fprintf(stderr, "  %.3g m: grid %d x %d (%.3g cells)\n", res, geo.size_x, geo.size_y,
                 static_cast<double>(geo.num_cells()));
    for (const LargeBackend &b : chosen) rows.push_back(run_large(b, scans, p, opt.threads));
  }
  print_large_table(opt, rows);
  return 0;
}

}  // namespace bench

#endif  // VASCO_BENCH_LARGE_BENCH_H
