// align_bench — what finding the transform between two sessions' maps costs
// (vasco::align_maps, align.h), per backend, with its accuracy beside it
// (`make bench`; speed claims are made only through benchmarks).
//
// The case of issue 58: fr079 split into two sessions sharing part of the
// route, scans [0, 0.65 n) and [0.35 n, n), both mapped at 0.1 m; the second
// mapped in a frame moved by a transform T drawn from each seed, which
// align_maps must find. Per backend (the CPU on 1, 2 and every thread, the
// GPU where one is usable) and seed: the median time of align_maps over N
// runs after a warm-up (the maps made beforehand, not timed), the errors
// from T, the score and the verdict; then the targets, met or missed: at
// most 100 ms on the GPU (an H100 or H200), at most 3 s on 2 CPU threads.
//
//   align_bench [--runs N] [--cpu-runs N] [--seeds N] [--log FILE] [--quick]
//   --quick: 1 seed, 1 CPU run, no 1-thread row.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "vasco_gpu/align.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/internal/parallel.h"
#include "vasco_gpu/internal/se2.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/pipeline/log_scans.h"
#if defined(VASCO_HAVE_CUDA)
#include "vasco_gpu/cuda_backend.h"
#endif

namespace {

using Clock = std::chrono::steady_clock;
using vasco::AlignMap;
using vasco::AlignOptions;
using vasco::AlignResult;
using vasco::Pose2;

constexpr double kPi = 3.14159265358979323846;
constexpr double kCell = 0.1;
constexpr double kGpuTargetMs = 100, kCpu2TargetMs = 3000;

struct Options {
  int runs = 20, cpu_runs = 3, seeds = 3;
  bool quick = false;
  std::string log = "fr079-complete.gfs.log.gz";
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n == 0 ? 0 : n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

vasco::MapperParams params_at_cell() {
  vasco::MapperParams p;
  p.resolution = kCell;
  p.downsample = 1;
  p.border = 5;
  return p;
}

AlignMap map_of(const vasco::ScanBatch &scans) {
  vasco::Mapper m(params_at_cell(), "cpu_threads");
  m.insert(scans);
  return vasco::align_map_of(m.finish(), m.frame());
}

// One seed's case: the reference half, the moved second half, the truth.
struct Case {
  Pose2 truth;
  AlignMap moving;
};

struct Backend {
  std::string label;
  AlignOptions options;
  bool gpu = false;
  double target_ms = 0;  // 0: none
};

std::vector<Backend> backends(bool gpu, bool quick) {
  std::vector<Backend> b;
  auto cpu = [](int threads, double target) {
    Backend x;
    x.label = "cpu, " + std::to_string(threads) + (threads == 1 ? " thread" : " threads");
    x.options.backend = AlignOptions::Backend::Cpu;
    x.options.threads = threads;
    x.target_ms = target;
    return x;
  };
  if (!quick) b.push_back(cpu(1, 0));
  b.push_back(cpu(2, kCpu2TargetMs));
  if (vasco::hardware_threads() > 2) b.push_back(cpu(vasco::hardware_threads(), 0));
  if (gpu) {
    Backend g;
    g.label = "gpu";
    g.options.backend = AlignOptions::Backend::Gpu;
    g.gpu = true;
    g.target_ms = kGpuTargetMs;
    b.push_back(g);
  }
  return b;
}

struct Row {
  std::string backend;
  int seed = 0;
  double ms = 0, error_m = 0, error_deg = 0, score = 0;
  std::string verdict;
  int rotations = 0, points = 0;
};

Row measure(const AlignMap &reference, const Case &c, const Backend &b, int runs, int seed) {
  AlignResult r = vasco::align_maps(reference, c.moving, b.options);  // warm-up (and the GPU's context)
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = Clock::now();
    r = vasco::align_maps(reference, c.moving, b.options);
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  Row row;
  row.backend = b.label;
  row.seed = seed;
  row.ms = median(ms);
  row.error_m = std::hypot(r.best.x - c.truth.x, r.best.y - c.truth.y);
  row.error_deg = std::abs(std::remainder(r.best.theta - c.truth.theta, 2 * kPi)) * 180 / kPi;
  row.score = r.best.score;
  row.verdict = vasco::align_verdict_name(r.verdict);
  row.rotations = r.rotations;
  row.points = r.moving_points;
  return row;
}

// Each target met or missed, by the slowest seed's median.
void print_targets(const std::vector<Backend> &bs, const std::vector<Row> &rows, const std::string &gpu_name) {
  std::printf("\nTargets (issue 58; the slowest seed's median):\n");
  for (const Backend &b : bs) {
    if (b.target_ms <= 0) continue;
    double worst = 0;
    bool all_aligned = true;
    for (const Row &r : rows)
      if (r.backend == b.label) {
        worst = std::max(worst, r.ms);
        all_aligned = all_aligned && r.verdict == "aligned" && r.error_m <= kCell && r.error_deg <= 0.5;
      }
    std::printf("  %-16s <= %6.0f ms: %9.1f ms, %s%s%s\n", b.label.c_str(), b.target_ms, worst,
                worst <= b.target_ms ? "met" : "missed", all_aligned ? "" : " (NOT within 0.1 m and 0.5 deg)",
                b.gpu ? (" on " + gpu_name).c_str() : "");
  }
}

int parse(int argc, char **argv, Options *o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) o->runs = std::atoi(argv[++i]);
    else if (a == "--cpu-runs" && i + 1 < argc) o->cpu_runs = std::atoi(argv[++i]);
    else if (a == "--seeds" && i + 1 < argc) o->seeds = std::atoi(argv[++i]);
    else if (a == "--log" && i + 1 < argc) o->log = argv[++i];
    else if (a == "--quick") o->quick = true;
    else return 2;
  }
  if (o->quick) o->seeds = 1, o->cpu_runs = 1;
  return o->runs > 0 && o->cpu_runs > 0 && o->seeds > 0 ? 0 : 2;
}

}  // namespace

int main(int argc, char **argv) {
  Options opt;
  if (parse(argc, argv, &opt) != 0) {
    std::fprintf(stderr, "usage: align_bench [--runs N] [--cpu-runs N] [--seeds N] [--log FILE] [--quick]\n");
    return 2;
  }
  std::string why, gpu_name = "no GPU";
  const bool gpu = vasco::gpu_usable(0, &why);
#if defined(VASCO_HAVE_CUDA)
  if (gpu) gpu_name = vasco::cuda_device_description(0);
#endif
  std::printf(gpu ? "GPU: %s\n" : "%s: CPU rows only.\n", gpu ? gpu_name.c_str() : why.c_str());
  const std::string path = opt.log.find('/') == std::string::npos ? std::string(VASCO_SOURCE_DIR) + "/logs/" + opt.log
                                                                   : opt.log;
  vasco::LogLoadStats stats;
  const vasco::ScanBatch all = vasco::load_scans(path, params_at_cell(), carmen::LogReaderOptions{}, &stats);
  const long n = static_cast<long>(all.num_scans());
  const AlignMap reference = map_of(all.select(0, n * 65 / 100));
  const vasco::ScanBatch second = all.select(n * 35 / 100, n - n * 35 / 100);
  std::vector<Case> cases;
  for (int seed = 0; seed < opt.seeds; ++seed) {
    std::mt19937 rng(static_cast<unsigned>(seed));
    std::uniform_real_distribution<double> shift(-20, 20), turn(-kPi, kPi);
    Case c;
    const double x = shift(rng), y = shift(rng);
    c.truth = {x, y, turn(rng)};
    vasco::ScanBatch moved = second;
    const Pose2 to_frame = vasco::inverse(c.truth);
    moved.transform(to_frame.x, to_frame.y, to_frame.theta);
    c.moving = map_of(moved);
    cases.push_back(std::move(c));
  }
  const std::vector<Backend> bs = backends(gpu, opt.quick);
  std::vector<Row> rows;
  for (const Backend &b : bs)
    for (int seed = 0; seed < opt.seeds; ++seed) {
      rows.push_back(measure(reference, cases[static_cast<size_t>(seed)], b, b.gpu ? opt.runs : opt.cpu_runs, seed));
      std::fprintf(stderr, "  %s seed %d done\n", b.label.c_str(), seed);
    }
  std::printf("\nAligning two halves of %s at %.1f m (scans [0, 0.65 n) and [0.35 n, n) of %ld; the second moved by\n"
              "T drawn from the seed); median of %d runs on the GPU, %d on the CPU, after a warm-up; reference %d x %d "
              "cells\n\n",
              opt.log.c_str(), kCell, n, opt.runs, opt.cpu_runs, reference.size_x, reference.size_y);
  std::printf("| backend | seed | T (x, y, theta) | median ms | 1 thread / this | error m | error deg | score | verdict |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const Row &r : rows) {
    const Pose2 &t = cases[static_cast<size_t>(r.seed)].truth;
    double one_thread = 0;
    for (const Row &o : rows)
      if (o.seed == r.seed && o.backend == "cpu, 1 thread") one_thread = o.ms;
    const std::string ratio = one_thread > 0 ? std::to_string(one_thread / r.ms).substr(0, 5) : "-";
    std::printf("| %s | %d | (%.2f, %.2f, %.3f) | %.1f | %s | %.4f | %.3f | %.3f | %s |\n", r.backend.c_str(), r.seed,
                t.x, t.y, t.theta, r.ms, ratio.c_str(), r.error_m, r.error_deg, r.score, r.verdict.c_str());
  }
  if (!rows.empty())
    std::printf("\n(%d moving wall cells at 0.1 m, %d rotations in the global search)\n", rows[0].points,
                rows[0].rotations);
  print_targets(bs, rows, gpu_name);
  return 0;
}
