// mapping_bench — the benchmark harness behind `make bench` (speed claims
// are made only through it; see docs/performance.md).
//
// For each dataset (fr079-complete.gfs: 4791 x 360; fr101.carmen full rate:
// 4758 x 360) and parameter set (paper: range_max 6.4 m at 2.5 cm, as in the
// paper; vasco_default_raw: vasco's defaults, see below) it runs every backend
// — cpu_double (one core), cpu_threads (all cores, exact), cpu_float, cuda
// float, cuda exact — through a mapping session as log2map does (a fresh
// vasco::Mapper per run, every scan inserted, finish on the GPU for cuda) —
// a warm-up and then N timed runs, and prints the median
// of each phase: parse, prep (host-side beam placement of the GPU backends),
// upload, map (GPU: kernels only, CUDA events), download, finish, write
// (.map.gz), total; cell updates per second of the map phase, and the
// speed-up of the map phase over cpu_double and over cpu_threads measured in
// the same run. A second table is the ablation of the paper's kernel design.
// Without a usable GPU it runs the CPU rows and says so.
//
// --large instead maps a synthetic large site (bench/large_site.h: a square
// loop of corridors, the robot starting in a corner, so that the grid passes
// 2^31 cells at vasco's 2.5 cm) with every backend at each --large-res, and
// prints grid cells, scans, map and finish time and peak host and device
// memory per backend (bench/large_bench.h).
//
//   mapping_bench [--runs N] [--quick] [--threads N] [--no-ablation] [--dataset NAME] [--split N]
//                 [--backends cpu_double,cpu_threads,cpu_float,cuda_float,cuda_exact]
//
// --backends keeps only the rows named (a row's label with '_' for ' '); the
// speed-up columns need cpu_double and cpu_threads in the same run ('-' without).
//
// --split N adds the CUDA rows again with each render split in N bands of
// columns over the GPUs there are (split_renderer.h; band i on GPU i % count).
//   mapping_bench --large [--large-scans N] [--large-site M] [--large-res R,R..]
//                 [--large-backends cpu_double,cpu_threads,cpu_float,cuda_float,cuda_exact] [--threads N]
//
// --thread-scaling instead times cpu_threads' map phase at 1, 2, 4, ... threads
// up to the cores there are (or --scaling-threads LIST) beside cpu_double and
// cpu_float on one core (bench/thread_scaling.h).
//   mapping_bench --thread-scaling [--scaling-threads N,N..] [--runs N] [--dataset NAME]
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bench_support.h"
#include "large_bench.h"
#include "thread_scaling.h"
#include "carmen_compat/map_file.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/internal/cpu_threads_backend.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/internal/parallel.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/renderer.h"
#include "vasco_gpu/pipeline/log_scans.h"
#if defined(VASCO_HAVE_CUDA)
#include "paper_backend.h"
#include "vasco_gpu/cuda_backend.h"
#endif

namespace {

using bench::bench_datasets;
using bench::bench_param_sets;
using bench::Dataset;
using bench::median;
using bench::ms;
using bench::self_dir;
using bench::shell_quoted;
using bench::temp_map_path;
using bench::now_s;
using bench::ParamSet;

using Clock = std::chrono::steady_clock;

struct BackendSpec {
  std::string label;
  std::string factory;  // the backend name a Mapper takes
  vasco::BackendOptions options;
  bool gpu = false;
};

struct Phases {
  std::vector<double> prep, upload, map, download, finish, write, total;
  vasco::MapStats stats;
};

struct Row {
  std::string dataset, params, backend;
  uint64_t scans = 0, beams = 0, updates = 0;
  double parse = 0, prep = 0, upload = 0, map = 0, download = 0, finish = 0, write = 0, total = 0;
};

// Writes a finished map as a .map.gz to a temporary file and removes it
// (the write phase of a run).
void write_and_discard(const vasco::FinishedMap &fin) {
  carmen::MapFile mf;
  carmen::GridMap g;
  g.size_x = fin.size_x;
  g.size_y = fin.size_y;
  g.resolution = fin.resolution;
  g.cells = fin.cells;
  mf.gridmap = std::move(g);
  const std::string out = temp_map_path();
  carmen::write_map_file(out, mf);
  std::remove(out.c_str());
}

// One run's phases, from its stats and the times t0 (start), t1 (mapped),
// t2 (finished), t3 (written). map: CPU backends the wall time, GPU
// backends the kernels (events).
void record(Phases *ph, const vasco::MapStats &st, bool gpu, double t0, double t1, double t2, double t3) {
  ph->prep.push_back(st.prep_s);
  ph->upload.push_back(st.upload_s);
  ph->map.push_back(gpu ? st.map_s : (t1 - t0));
  ph->download.push_back(st.download_s);
  ph->finish.push_back(t2 - t1);
  ph->write.push_back(t3 - t2);
  ph->total.push_back(t3 - t0);
  ph->stats = st;
}

#if defined(VASCO_HAVE_CUDA)
// One timed run of a GPU map alone (the paper's kernels, which only map whole
// batches, and ours for comparison): `map` fills the grid, then finish, write.
void run_once(const std::function<std::vector<float>(vasco::MapStats *)> &map, const vasco::MapperParams &p,
              const vasco::GridGeometry &geo, Phases *ph) {
  const double t0 = now_s();
  vasco::MapStats st;
  std::vector<float> cells = map(&st);
  const double t1 = now_s();
  const vasco::FinishedMap fin = vasco::finish_grid(cells.data(), geo.size_x, geo.size_y, geo.resolution,
                                                    static_cast<int>(p.downsample), static_cast<int>(p.border));
  const double t2 = now_s();
  write_and_discard(fin);
  record(ph, st, true, t0, t1, t2, now_s());
}
#endif

// One timed run through a mapping session, as log2map maps a log: a fresh
// session, every scan inserted, finish (on the GPU for cuda), write.
void run_session_once(const BackendSpec &spec, int threads, const vasco::ScanBatch &batch,
                      const vasco::MapperParams &p, Phases *ph) {
  vasco::BackendOptions o = spec.options;
  o.threads = threads;
  const double t0 = now_s();
  vasco::Mapper m(p, spec.factory, o);
  m.insert(batch);
  const vasco::MapStats st = m.last_stats();
  const double t1 = now_s();
  const vasco::FinishedMap fin = m.finish();
  const double t2 = now_s();
  write_and_discard(fin);
  record(ph, st, spec.gpu, t0, t1, t2, now_s());
}

void print_rule(int width) { std::printf("%s\n", std::string(width, '-').c_str()); }

// Wall time of a whole log2map process (start to file written), median of runs.
double log2map_wall(const std::string &bin, const std::string &log, const std::string &backend,
                    int runs) {
  std::vector<double> t;
  const std::string out = temp_map_path();
  const std::string cmd =
      shell_quoted(bin) + " --quiet --backend " + backend + " " + shell_quoted(log) + " " + shell_quoted(out) +
      " > /dev/null 2>&1";
  for (int i = 0; i < runs + 1; ++i) {
    const double t0 = now_s();
    const int rc = std::system(cmd.c_str());
    const double t1 = now_s();
    std::remove(out.c_str());
    if (rc != 0) return -1;
    if (i > 0) t.push_back(t1 - t0);
  }
  return median(t);
}

// The command line.
struct Options {
  int runs = 5, threads = 0;
  bool ablation = true;
  std::string only;  // --dataset: only this one
  int split = 0;     // --split N: the CUDA rows again, each render split in N bands over the GPUs
  std::vector<std::string> backends;  // --backends: only these rows (empty: all)
  bench::LargeOptions large;  // --large and its options
  bench::ScalingOptions scaling;  // --thread-scaling and its options
};

constexpr const char *kUsage =
    "usage: mapping_bench [--runs N] [--quick] [--threads N] [--no-ablation] [--dataset fr079|fr101] [--split N]\n"
    "                     [--backends cpu_double,cpu_threads,cpu_float,cuda_float,cuda_exact]\n"
    "       mapping_bench --large [--large-scans N] [--large-site METRES] [--large-res R[,R...]]\n"
    "                     [--large-backends cpu_double,cpu_threads,cpu_float,cuda_float,cuda_exact] [--threads N]\n"
    "       mapping_bench --thread-scaling [--scaling-threads N[,N...]] [--runs N] [--dataset fr079|fr101]\n";

// Parses the command line into *o (threads 0 or less: all cores); false, after the usage line on stderr,
// for anything it does not know.
bool parse_options(int argc, char **argv, Options *o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) o->runs = std::max(1, std::atoi(argv[++i]));
    else if (a == "--quick") o->runs = 1;
    else if (a == "--threads" && i + 1 < argc) o->threads = std::atoi(argv[++i]);
    else if (a == "--no-ablation") o->ablation = false;
    else if (a == "--dataset" && i + 1 < argc) o->only = argv[++i];
    else if (a == "--split" && i + 1 < argc) o->split = std::max(0, std::min(64, std::atoi(argv[++i])));
    else if (a == "--backends" && i + 1 < argc) o->backends = bench::split_names(argv[++i]);
    else if (a == "--large") o->large.on = true;
    else if (a == "--large-scans" && i + 1 < argc) o->large.site.scans = std::max(1L, std::atol(argv[++i]));
    else if (a == "--large-site" && i + 1 < argc) {
      o->large.site.side = std::atof(argv[++i]);
      if (!(o->large.site.side > 2 * o->large.site.corridor)) {
        std::fprintf(stderr, "mapping_bench: --large-site must be more than %g m\n", 2 * o->large.site.corridor);
        return false;
      }
    } else if (a == "--large-res" && i + 1 < argc) {
      if (!bench::parse_number_list(argv[++i], &o->large.resolutions)) {
        std::fprintf(stderr, "mapping_bench: --large-res takes positive numbers, comma-separated\n%s", kUsage);
        return false;
      }
    } else if (a == "--large-backends" && i + 1 < argc) o->large.backends = bench::split_names(argv[++i]);
    else if (a == "--thread-scaling") o->scaling.on = true;
    else if (a == "--scaling-threads" && i + 1 < argc) {
      if (!bench::parse_int_list(argv[++i], &o->scaling.threads)) {
        std::fprintf(stderr, "mapping_bench: --scaling-threads takes thread counts from 1, comma-separated\n%s",
                     kUsage);
        return false;
      }
    } else {
      std::fprintf(stderr, "%s", kUsage);
      return false;
    }
  }
  if (o->threads <= 0) o->threads = vasco::hardware_threads();
  o->large.threads = o->threads;
  o->scaling.runs = o->runs;
  o->scaling.only = o->only;
  return true;
}

// Whether a GPU is usable, what it is (or why not), and how long the CUDA context took to start.
struct GpuInfo {
  bool usable = false;
  std::string desc = "none";
  double init_s = 0;
};

// Probes device 0 (starting the CUDA context) when built with CUDA.
GpuInfo probe_gpu() {
  GpuInfo g;
#if defined(VASCO_HAVE_CUDA)
  const double t0 = now_s();
  std::string why;
  g.usable = vasco::cuda_usable(0, &why);
  g.init_s = now_s() - t0;
  g.desc = g.usable ? vasco::cuda_device_description(0) : "none (" + why + ")";
#else
  g.desc = "none (built without CUDA)";
#endif
  return g;
}

// Band i of a split render on GPU i % (the GPUs there are).
std::vector<int> split_devices(int parts) {
  const int count = std::max(vasco::cuda_device_count(), 1);
  std::vector<int> devices;
  for (int i = 0; i < parts; ++i) devices.push_back(i % count);
  return devices;
}

// The backends measured: the CPU ones, and both CUDA modes when a GPU is
// usable (again split in `split` bands, "cuda float/N", for split >= 2).
std::vector<BackendSpec> backend_specs(bool gpu, int split) {
  std::vector<BackendSpec> specs = {{"cpu_double", "cpu_double", {}, false},
                                    {"cpu_threads", "cpu_threads", {}, false},
                                    {"cpu_float", "cpu_float", {}, false}};
  if (gpu) {
    vasco::BackendOptions f, e;
    e.cuda_mode = vasco::CudaMode::Exact;
    specs.push_back({"cuda float", "cuda", f, true});
    specs.push_back({"cuda exact", "cuda", e, true});
    if (split >= 2) {
      f.split_devices = e.split_devices = split_devices(split);
      specs.push_back({"cuda float/" + std::to_string(split), "cuda", f, true});
      specs.push_back({"cuda exact/" + std::to_string(split), "cuda", e, true});
    }
  }
  return specs;
}

// The specs whose label, with '_' for ' ', --backends names (all when it names none).
std::vector<BackendSpec> chosen_specs(std::vector<BackendSpec> specs, const std::vector<std::string> &names) {
  if (names.empty()) return specs;
  std::vector<BackendSpec> kept;
  for (const BackendSpec &s : specs) {
    std::string name = s.label;
    std::replace(name.begin(), name.end(), ' ', '_');
    if (std::find(names.begin(), names.end(), name) != names.end()) kept.push_back(s);
  }
  return kept;
}

// The lines above the table: runs, threads, GPU.
void print_header(const Options &opt, const GpuInfo &gpu) {
  std::printf("vasco_gpu mapping_bench: median of %d runs after a warm-up; times in ms\n", opt.runs);
  std::printf("CPU threads: %d; GPU: %s", opt.threads, gpu.desc.c_str());
  if (gpu.usable) std::printf(" (CUDA context start-up %.0f ms, not in the rows)", gpu.init_s * 1e3);
  std::printf("\n");
  if (!gpu.usable) std::printf("No usable GPU: CPU rows only.\n");
  if (gpu.usable && opt.split >= 2) {
    const int count = std::max(vasco::cuda_device_count(), 1);
    std::printf("cuda float/%d, cuda exact/%d: each render split in %d bands of columns over %d GPU%s%s\n", opt.split,
                opt.split, opt.split, std::min(count, opt.split), std::min(count, opt.split) > 1 ? "s" : "",
                count < opt.split ? " (bands sharing a GPU run one after another on it: the split's cost, not its gain)"
                                  : "");
  }
}

// Ablation results: "dataset / params" -> (variant, median map time) in the order run.
using AblationRows = std::map<std::string, std::vector<std::pair<std::string, double>>>;
// The ablation rows of the float target's floors (print_targets): the walk with its updates added in
// registers (no memory: what is left when adding costs nothing) and in a shared-memory tile.
constexpr const char *kFloorRegisters = "  floor: updates added in registers (the walk alone)";
constexpr const char *kFloorSharedTile = "  floor: updates added to a 64x64 tile in shared memory";

// What the benchmark sections share: the options, the backends, whether a GPU is usable, and the
// results gathered so far.
struct Bench {
  Options opt;
  std::vector<BackendSpec> specs;
  bool gpu = false;
  std::vector<Row> rows;
  AblationRows ablation_rows;
};

// Parses a log with a parameter set a warm-up and then `runs` times; the timed runs' parse times go to
// *parse_t. Returns the scans.
vasco::ScanBatch timed_parse(const Dataset &ds, const ParamSet &ps, int runs, std::vector<double> *parse_t) {
  vasco::ScanBatch batch;
  for (int r = 0; r < runs + 1; ++r) {
    vasco::LogLoadStats ls;
    const double t0 = now_s();
    batch = vasco::load_scans(ds.path, ps.params, carmen::LogReaderOptions{}, &ls);
    if (r > 0) parse_t->push_back(now_s() - t0);
  }
  return batch;
}

// The table row of one backend: counts and the medians of its phases (total includes the parse).
Row make_row(const Dataset &ds, const ParamSet &ps, const BackendSpec &spec, const vasco::ScanBatch &batch,
             const std::vector<double> &parse_t, const Phases &ph) {
  Row row;
  row.dataset = ds.name;
  row.params = ps.name;
  row.backend = spec.label;
  row.scans = batch.num_scans();
  row.beams = ph.stats.beams_used;
  row.updates = ph.stats.cell_updates;
  row.parse = median(parse_t);
  row.prep = median(ph.prep);
  row.upload = median(ph.upload);
  row.map = median(ph.map);
  row.download = median(ph.download);
  row.finish = median(ph.finish);
  row.write = median(ph.write);
  row.total = row.parse + median(ph.total);
  return row;
}

// Every backend through a mapping session on one log and parameter set: a warm-up, then the timed runs,
// one table row each.
void bench_backends(Bench *b, const Dataset &ds, const ParamSet &ps, const vasco::ScanBatch &batch,
                    const std::vector<double> &parse_t) {
  for (const BackendSpec &spec : b->specs) {
    std::fprintf(stderr, "  %s ...\n", spec.label.c_str());
    Phases ph, warm;
    run_session_once(spec, b->opt.threads, batch, ps.params, &warm);
    for (int r = 0; r < b->opt.runs; ++r) run_session_once(spec, b->opt.threads, batch, ps.params, &ph);
    b->rows.push_back(make_row(ds, ps, spec, batch, parse_t, ph));
  }
}

#if defined(VASCO_HAVE_CUDA)
// The ablation of the paper's kernel design on one log and parameter set: each variant a warm-up and
// then the timed runs, the median map time recorded.
void bench_ablation(Bench *b, const Dataset &ds, const ParamSet &ps, const vasco::ScanBatch &batch,
                    const vasco::GridGeometry &geo) {
  using vasco::cuda::PaperVariant;
  const std::pair<const char *, int> variants[] = {
      {"paper: launch per scan, beam data in shared, params in constant", int(PaperVariant::PerScan)},
      {"  - without shared memory (each thread places the beam)", int(PaperVariant::PerScanNoShared)},
      {"  - without constant memory (params from global)", int(PaperVariant::PerScanNoConst)},
      {"  + all scans fused into one launch", int(PaperVariant::Fused)},
      {"ours: warp per beam, block per scan, one launch", -1},
      // The floors of our accumulation (the issue of a float map kernel <= 0.6 ms): the same walk, the
      // updates to registers (no layout of the sums beats it), or to a shared tile never flushed (a
      // per-tile layout, before its binning and flushes).
      {kFloorRegisters, int(PaperVariant::FloorRegisters)},
      {kFloorSharedTile, int(PaperVariant::FloorSharedTile)}};
  for (const auto &v : variants) {
    std::function<std::vector<float>(vasco::MapStats *)> map;
    std::shared_ptr<vasco::Renderer> ours;
    std::shared_ptr<vasco::PaperMapper> paper;
    if (v.second < 0) {
      ours = vasco::make_renderer("cuda");
      map = [&](vasco::MapStats *st) { return vasco::render_grid(*ours, batch, ps.params, geo, st); };
    } else {
      paper = vasco::make_paper_mapper(static_cast<PaperVariant>(v.second));
      map = [&](vasco::MapStats *st) { return paper->map(batch, ps.params, geo, st); };
    }
    // A floor leaves the grid unknown (its sums are never turned into cells): its kernel is timed alone,
    // with no map to finish or write.
    const bool floor = v.second == int(PaperVariant::FloorRegisters) || v.second == int(PaperVariant::FloorSharedTile);
    const auto once = [&](Phases *p) {
      if (!floor) return run_once(map, ps.params, geo, p);
      vasco::MapStats st;
      map(&st);
      p->map.push_back(st.map_s);
    };
    Phases ph, warm;
    once(&warm);
    for (int r = 0; r < b->opt.runs; ++r) once(&ph);
    b->ablation_rows[ds.name + " / " + ps.name].push_back({v.first, median(ph.map)});
  }
}
#endif

// One log with one parameter set: the parse, every backend, and the ablation when asked for and a GPU is
// usable.
void bench_param_set(Bench *b, const Dataset &ds, const ParamSet &ps) {
  // Parse: the same for every backend.
  std::vector<double> parse_t;
  const vasco::ScanBatch batch = timed_parse(ds, ps, b->opt.runs, &parse_t);
  const vasco::GridGeometry geo = vasco::size_grid(batch, ps.params);
  std::fprintf(stderr, "%s / %s: %zu scans, grid %d x %d\n", ds.name.c_str(), ps.name.c_str(),
               batch.num_scans(), geo.size_x, geo.size_y);
  bench_backends(b, ds, ps, batch, parse_t);
#if defined(VASCO_HAVE_CUDA)
  if (b->gpu && b->opt.ablation) bench_ablation(b, ds, ps, batch, geo);
#endif
}

// One log with every parameter set, unless --dataset names another or the log is missing.
void bench_dataset(Bench *b, const Dataset &ds) {
  if (!b->opt.only.empty() && ds.name != b->opt.only) return;
  if (access(ds.path.c_str(), R_OK) != 0) {
    std::printf("%s: %s not found, skipped\n", ds.name.c_str(), ds.path.c_str());
    return;
  }
  for (const ParamSet &ps : bench_param_sets()) bench_param_set(b, ds, ps);
}

// a / b to one decimal, '-' where either is missing.
std::string ratio(double a, double b) {
  if (!(a > 0 && b > 0)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", a / b);
  return buf;
}

// The main table, one line per row, with the speed-ups over cpu_double and cpu_threads of the same data,
// and its legend.
void print_table(const std::vector<Row> &rows) {
  const int width = 179;
  print_rule(width);
  std::printf("%-6s %-17s %-14s %5s %8s %10s %7s %7s %7s %8s %8s %7s %6s %8s %9s %8s %8s\n", "data",
              "params", "backend", "scans", "beams", "updates", "parse", "prep", "upload", "map",
              "download", "finish", "write", "total", "Mupd/s", "x1core", "xthreads");
  print_rule(width);
  for (const Row &r : rows) {
    double base = 0, threads_map = 0;
    for (const Row &o : rows)
      if (o.dataset == r.dataset && o.params == r.params) {
        if (o.backend == "cpu_double") base = o.map;
        if (o.backend == "cpu_threads") threads_map = o.map;
      }
    std::printf("%-6s %-17s %-14s %5llu %8llu %10llu %7s %7s %7s %8s %8s %7s %6s %8s %9.0f %8s %8s\n",
                r.dataset.c_str(), r.params.c_str(), r.backend.c_str(), (unsigned long long)r.scans,
                (unsigned long long)r.beams, (unsigned long long)r.updates, ms(r.parse).c_str(),
                ms(r.prep).c_str(), ms(r.upload).c_str(), ms(r.map).c_str(), ms(r.download).c_str(),
                ms(r.finish).c_str(), ms(r.write).c_str(), ms(r.total).c_str(),
                r.map > 0 ? r.updates / r.map / 1e6 : 0.0, ratio(base, r.map).c_str(),
                ratio(threads_map, r.map).c_str());
  }
  print_rule(width);
  std::printf("map = the update itself: CPU rows the wall time of the backend (cpu_threads'\n"
              "prep included), GPU rows the kernels only (CUDA events; the host-side beam\n"
              "placement is prep). total = parse + the wall time of map, finish and write (GPU\n"
              "rows: prep, upload and download included). x1core / xthreads: map-phase\n"
              "speed-up over cpu_double and over cpu_threads on the same data in this run.\n");
}

// The performance targets on fr079 (map phase), each met or missed by how much, and why a miss is what
// it is (measured with Nsight Compute on an H200; see docs/performance.md, "History").
struct Target {
  const char *params, *backend;
  double limit_ms;
  const char *why_missed;
  const char *floor;  // the ablation row that bounds it from below, or null
};

// The ablation's row `label` on `key` (data / parameters), in seconds; < 0 when not run.
double ablation_row(const AblationRows &ablation, const std::string &key, const std::string &label) {
  const auto it = ablation.find(key);
  if (it == ablation.end()) return -1;
  for (const auto &v : it->second)
    if (v.first == label) return v.second;
  return -1;
}

void print_targets(const std::vector<Row> &rows, const AblationRows &ablation) {
  static const Target kTargets[] = {
      {"vasco_default_raw", "cuda float", 0.6,
       "one 64-bit atomic add into L2 per update past a beam's first 32 steps (fixed point, for the same "
       "bytes every run; the first 32 go to shared memory), the L2 about 75 % busy",
       kFloorSharedTile},
      {"vasco_default_raw", "cuda exact", 5.0,
       "the light tiles' total work (the heavy tiles, where the robot stood, run beside them): each tile's "
       "list applied in order, a dependent chain of double divisions per update that changes a cell, the "
       "SMs busy all through the tiles kernel (3.8 ms); the tile lists' pairs, sort and order take 1.2 ms",
       nullptr},
  };
  bool header = false;
  for (const Target &t : kTargets)
    for (const Row &r : rows) {
      if (r.dataset != "fr079" || r.params != t.params || r.backend != t.backend) continue;
      if (!header) std::printf("\nTargets (fr079, map phase):\n");
      header = true;
      const double got = r.map * 1e3;
      // Three decimals: a miss of a few microseconds must not read as "missed by 0.00".
      std::printf("  %-11s %-17s <= %.1f ms: %.3f ms, %s", t.backend, t.params, t.limit_ms, got,
                  got <= t.limit_ms ? "met\n" : "missed by ");
      if (got <= t.limit_ms) continue;
      std::printf("%.3f ms: bound by %s\n", got - t.limit_ms, t.why_missed);
      const double floor = t.floor ? ablation_row(ablation, r.dataset + " / " + r.params, t.floor) * 1e3 : -1;
      if (floor >= 0)
        std::printf("    floor of a per-tile layout (ablation, \"%s\"): %.3f ms, %s\n", t.floor, floor,
                    floor <= t.limit_ms ? "below the target: a per-tile layout could meet it"
                                        : "above the target: no per-tile layout meets it");
      const double walk = t.floor ? ablation_row(ablation, r.dataset + " / " + r.params, kFloorRegisters) * 1e3 : -1;
      if (walk >= 0 && floor >= 0)
        std::printf("    the walk alone (ablation, \"%s\"): %.3f ms: %.3f ms of the target left for adding the "
                    "updates, which take %.3f ms in a shared tile and %.3f ms in ours\n",
                    kFloorRegisters, walk, t.limit_ms - walk, floor - walk, got - walk);
    }
}

// The ablation table, when there is one.
void print_ablation(const AblationRows &ablation_rows) {
  if (ablation_rows.empty()) return;
  std::printf("\nAblation of the paper's kernel (float, no lost updates), map phase in ms:\n");
  for (const auto &kv : ablation_rows) {
    std::printf("  %s\n", kv.first.c_str());
    for (const auto &v : kv.second) std::printf("    %-66s %9s\n", v.first.c_str(), ms(v.second).c_str());
  }
}

// End to end: a whole log2map process (the one beside this binary) on fr079 to .map.gz, when there is
// one and fr079 is benchmarked.
void print_end_to_end(const char *argv0, const std::string &fr079, const Options &opt) {
  const std::string log2map = self_dir(argv0) + "/log2map";
  if (access(log2map.c_str(), X_OK) != 0 || !(opt.only.empty() || opt.only == "fr079")) return;
  std::printf("\nlog2map end to end (process start to .map.gz written), fr079, median of %d:\n", opt.runs);
  for (const char *b : {"cpu_double", "auto"}) {
    const double t = log2map_wall(log2map, fr079, b, opt.runs);
    std::printf("  --backend %-10s %8s ms\n", b, t < 0 ? "failed" : ms(t).c_str());
  }
}

}  // namespace

int main(int argc, char **argv) {
  Bench b;
  if (!parse_options(argc, argv, &b.opt)) return 2;
  if (b.opt.large.on) return bench::run_large_bench(b.opt.large);
  if (b.opt.scaling.on) return bench::run_thread_scaling(b.opt.scaling);
  const std::vector<Dataset> datasets = bench_datasets();
  const GpuInfo gpu = probe_gpu();
  b.gpu = gpu.usable;
  b.specs = chosen_specs(backend_specs(gpu.usable, b.opt.split), b.opt.backends);
  print_header(b.opt, gpu);
  for (const Dataset &ds : datasets) bench_dataset(&b, ds);
  print_table(b.rows);
  print_targets(b.rows, b.ablation_rows);
  print_ablation(b.ablation_rows);
  print_end_to_end(argv[0], datasets[0].path, b.opt);
  return 0;
}
