// golden_support.h — running our paths on CARMEN's golden cases: the case
// list (a SHA256SUMS file of GRIDMAP payload digests), where each case's log
// and parameter set live, every exact path (the backends and the egrid.h C
// API driven by the golden PROTOCOL's steps), and the DESIGN §4 comparison of
// a float path with a golden map. Shared by golden_test, float_golden_test
// and the golden_check tool (`make golden`).
#ifndef VASCO_TESTS_GOLDEN_SUPPORT_H
#define VASCO_TESTS_GOLDEN_SUPPORT_H

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <sys/stat.h>
#include <vector>

#include "carmen/egrid.h"
#include "carmen_compat/map_file.h"
#include "vasco_gpu/backend.h"
#include "carmen_compat/map_compare.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/pipeline/log_input.h"
#include "carmen_compat/map_digest.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/renderer.h"
#if defined(VASCO_HAVE_CUDA)
#include "vasco_gpu/cuda_backend.h"
#endif

namespace vasco {
namespace golden {

// A golden case: `<log>__<params>` and CARMEN's GRIDMAP payload digest.
struct Case {
  std::string name, log, params, sha256;
};

// gtest prints a parameter with this instead of its bytes.
inline void PrintTo(const Case &c, std::ostream *os) { *os << c.name; }

inline bool file_exists(const std::string &path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

// Reads "HASH  NAME" lines; throws naming the file and line on a bad one.
inline std::vector<Case> read_cases(const std::string &sums) {
  std::ifstream in(sums);
  if (!in) throw std::runtime_error(sums + ": cannot open");
  std::vector<Case> cases;
  std::string text;
  for (long line = 1; std::getline(in, text); ++line) {
    if (text.empty() || text[0] == '#') continue;
    std::istringstream fields(text);
    Case c;
    fields >> c.sha256 >> c.name;
    const size_t sep = c.name.find("__");
    if (c.sha256.size() != 64 || sep == std::string::npos)
      throw std::runtime_error(sums + ":" + std::to_string(line) + ": expected 'SHA256  LOG__PARAMS'");
    c.log = c.name.substr(0, sep);
    c.params = c.name.substr(sep + 2);
    cases.push_back(c);
  }
  return cases;
}

// The first of dir/LOG.log.gz over `dirs` that exists, or "".
inline std::string find_log(const std::string &log, const std::vector<std::string> &dirs) {
  for (const auto &d : dirs)
    if (file_exists(d + "/" + log + ".log.gz")) return d + "/" + log + ".log.gz";
  return "";
}

// The log and ini of a case, read as log2map reads them.
inline LogInput load_case(const std::string &log_path, const std::string &ini_path) {
  LogInputOptions o;
  o.log = log_path;
  o.param_file = ini_path;
  return load_log_input(o);
}

inline FinishedMap finish(const std::vector<float> &cells, const LogInput &in) {
  return finish_grid(cells.data(), in.geo.size_x, in.geo.size_y, in.geo.resolution,
                     static_cast<int>(in.params.downsample), static_cast<int>(in.params.border));
}

inline std::string digest(const FinishedMap &m) {
  return carmen::gridmap_payload_sha256(m.size_x, m.size_y, m.resolution, m.cells);
}

// The golden PROTOCOL's steps through CARMEN's C API (egrid.h): initialize
// with max_prob 0.99, one update per scan in order, finish. min_x / min_y of
// the result are not known through this API and are left 0.
inline FinishedMap run_egrid_c_api(const LogInput &in) {
  const MapperParams &p = in.params;
  evidence_grid g;
  const int init = carmen_mapper_initialize_evidence_grid(&g, in.geo.size_x, in.geo.size_y, p.resolution,
                                         in.geo.theta_offset, p.p_prior, p.p_occ, p.p_emp, 0.99,
                                         p.range_sure, p.range_max, p.wall_size);
  if (init != 0 || g.prob == nullptr) throw std::runtime_error("egrid: the grid could not be allocated");
  const ScanBatch &b = in.batch;
  for (size_t s = 0; s < b.num_scans(); ++s) {
    std::vector<float> ranges(b.ranges_of(s), b.ranges_of(s) + b.beams_in(s));
    carmen_mapper_update_evidence_grid(&g, b.x[s], b.y[s], b.theta[s], b.beams_in(s), ranges.data(),
                                       b.angle_step[s], b.first_angle[s]);
  }
  carmen_mapper_finish_evidence_grid(&g, static_cast<int>(p.downsample), static_cast<int>(p.border));
  FinishedMap m;
  m.size_x = g.size_x;
  m.size_y = g.size_y;
  m.resolution = g.resolution;
  m.downsample = static_cast<int>(p.downsample);
  m.cells.resize(static_cast<size_t>(g.size_x) * static_cast<size_t>(g.size_y));
  for (int x = 0; x < g.size_x; ++x)
    for (int y = 0; y < g.size_y; ++y) m.cells[static_cast<size_t>(x) * g.size_y + y] = g.prob[x][y];
  carmen_mapper_free_evidence_grid(&g);
  return m;
}

// The egrid.h C API on another backend's mapping session
// (vasco_egrid_set_backend), the default restored afterwards.
inline FinishedMap run_egrid_c_api_on(const std::string &backend, const LogInput &in) {
  vasco_egrid_set_backend(backend.c_str());
  try {
    FinishedMap m = run_egrid_c_api(in);
    vasco_egrid_set_backend("");
    return m;
  } catch (...) {
    vasco_egrid_set_backend("");
    throw;
  }
}

// A way of computing a case's map.
struct Path {
  std::string name;
  std::function<FinishedMap(const LogInput &)> run;
};

inline Path backend_path(const std::string &name, const std::string &backend, BackendOptions opt = {}) {
  return Path{name, [backend, opt](const LogInput &in) {
                auto r = make_renderer(backend, opt);
                return finish(render_grid(*r, in.batch, in.params, in.geo), in);
              }};
}

inline Path cpu_threads_path(int threads) {
  BackendOptions o;
  o.threads = threads;
  return backend_path("cpu_threads/" + std::to_string(threads), "cpu_threads", o);
}

inline Path cuda_path(CudaMode mode) {
  BackendOptions o;
  o.cuda_mode = mode;
  return backend_path(mode == CudaMode::Exact ? "cuda_exact" : "cuda_float", "cuda", o);
}

// CUDA exact mode split in two bands (BackendOptions::split_devices): on
// GPUs 0 and 1 where there are two, else both on GPU 0.
inline BackendOptions split_exact_options() {
  BackendOptions o;
  o.cuda_mode = CudaMode::Exact;
  o.split_devices = {0, cuda_device_count() >= 2 ? 1 : 0};
  return o;
}

inline Path cuda_split_path() { return backend_path("cuda_exact/split", "cuda", split_exact_options()); }

// Whether the CUDA backend can run here; `why` says why not.
inline bool cuda_available(std::string *why) {
#if defined(VASCO_HAVE_CUDA)
  return cuda_usable(0, why);
#else
  *why = "the CUDA backend is not compiled in";
  return false;
#endif
}

// In a GoogleTest test: skips it, saying why, where the CUDA backend cannot run.
#define REQUIRE_GPU()                                                                        \
  do {                                                                                       \
    std::string why_;                                                                        \
    if (!::vasco::golden::cuda_available(&why_)) GTEST_SKIP() << "no usable GPU: " << why_;  \
  } while (0)

// A mapping session fed the case's scans in pieces of 97 (vasco::Mapper):
// incremental inserts, frame growth and the renderer's finish.
// A session fed the scans in pieces of 97: its grid grows with a margin, so
// scans rendered into a grid of another size may round a cell position on
// a cell boundary the other way (mapper.hpp: the reservation). As it is: a
// path reported against CARMEN's map (golden_check's mapper-grown/...).
inline Mapper session_in_pieces(const LogInput &in, const std::string &backend, const BackendOptions &opt) {
  Mapper m(in.params, backend, opt);
  for (size_t a = 0; a < in.batch.num_scans(); a += 97) m.insert(in.batch.select(static_cast<long>(a), 97));
  if (m.frame().size_x != in.geo.size_x || m.frame().size_y != in.geo.size_y)
    throw std::runtime_error("the session's frame is not the PROTOCOL frame");
  return m;
}

inline Path mapper_grown_path(const std::string &backend, BackendOptions opt = {}) {
  return Path{"mapper-grown/" + backend,
              [backend, opt](const LogInput &in) { return session_in_pieces(in, backend, opt).finish(); }};
}

// The same session, then render(poses()): rendered again in frame() itself,
// what a SLAM pipeline does after moving poses — CARMEN's bytes.
inline Path mapper_path(const std::string &backend, BackendOptions opt = {}) {
  return Path{"mapper/" + backend, [backend, opt](const LogInput &in) {
                Mapper m = session_in_pieces(in, backend, opt);
                m.render(m.poses());
                return m.finish();
              }};
}

inline Path egrid_path(const std::string &backend) {
  return Path{"egrid_c_api/" + backend, [backend](const LogInput &in) { return run_egrid_c_api_on(backend, in); }};
}

// The paths DESIGN §4 promises CARMEN's bytes from, CPU ones first.
inline std::vector<Path> exact_cpu_paths() {
  return {backend_path("cpu_double", "cpu_double"), cpu_threads_path(1), cpu_threads_path(2),
          cpu_threads_path(7), Path{"egrid_c_api", run_egrid_c_api}, mapper_path("cpu_threads"),
          egrid_path("cpu_threads")};
}

// Re-indexes two finished maps of one grid (same downsample; crops given by
// min_x, min_y) onto their union box, unknown (-1) outside each crop, so that
// the DESIGN §4 table can compare maps cropped differently.
inline void to_union_box(const FinishedMap &a, const FinishedMap &b, std::vector<float> *ua,
                         std::vector<float> *ub) {
  const int x0 = std::min(a.min_x, b.min_x), y0 = std::min(a.min_y, b.min_y);
  const int x1 = std::max(a.min_x + a.size_x, b.min_x + b.size_x);
  const int y1 = std::max(a.min_y + a.size_y, b.min_y + b.size_y);
  const int nx = x1 - x0, ny = y1 - y0;
  auto place = [&](const FinishedMap &m, std::vector<float> *out) {
    out->assign(static_cast<size_t>(nx) * ny, -1.0f);
    for (int x = 0; x < m.size_x; ++x)
      for (int y = 0; y < m.size_y; ++y)
        (*out)[static_cast<size_t>(x + m.min_x - x0) * ny + (y + m.min_y - y0)] =
            m.cells[static_cast<size_t>(x) * m.size_y + y];
  };
  place(a, ua);
  place(b, ub);
}

inline carmen::Agreement compare_finished(const FinishedMap &ref, const FinishedMap &test) {
  std::vector<float> ur, ut;
  to_union_box(ref, test, &ur, &ut);
  return carmen::compare_maps(ur, ut);
}


// ---------------------------------------------------------------------------
// The test body every exact path runs (golden_test, golden_cuda_test).
// ---------------------------------------------------------------------------

// The golden cases the project carries: tests/data/golden (SHA256SUMS, params,
// the synthetic edge-case log, a few maps for cell-by-cell reports); the real
// logs are in logs/.
inline std::string carried_dir() { return std::string(VASCO_TEST_DATA_DIR) + "/golden"; }
inline std::vector<Case> carried_cases() { return read_cases(carried_dir() + "/SHA256SUMS"); }

// CARMEN's digest of the carried case `name` (`<log>__<params>`).
inline std::string carried_digest(const std::string &name) {
  for (const Case &c : carried_cases())
    if (c.name == name) return c.sha256;
  throw std::runtime_error(carried_dir() + "/SHA256SUMS: no case " + name);
}

// The GRIDMAP payload digest of the map file at `path` (what SHA256SUMS holds).
inline std::string map_file_digest(const std::string &path) {
  const carmen::MapFile mf = carmen::read_map_file(path);
  if (!mf.gridmap) return "no GRIDMAP in " + path;
  return carmen::gridmap_payload_sha256(mf.gridmap->size_x, mf.gridmap->size_y, mf.gridmap->resolution,
                                        mf.gridmap->cells);
}

// Where `got` departs from the golden map file, cell by cell (when the
// project carries that map).
inline std::string cell_report(const Case &c, const FinishedMap &got) {
  const std::string path = carried_dir() + "/maps/" + c.name + ".map.gz";
  if (!file_exists(path)) return "(no golden map carried for a cell-by-cell report)";
  const carmen::GridMap g = *carmen::read_map_file(path).gridmap;
  std::ostringstream r;
  r.precision(9);
  r << "golden " << g.size_x << " x " << g.size_y << " at " << float(g.resolution) << ", got "
    << got.size_x << " x " << got.size_y << " at " << float(got.resolution);
  if (g.size_x != got.size_x || g.size_y != got.size_y) return r.str();
  uint64_t n = 0;
  for (size_t i = 0; i < g.cells.size(); ++i) {
    if (std::memcmp(&g.cells[i], &got.cells[i], sizeof(float)) == 0) continue;
    if (n++ < 5)
      r << "\n  cell (" << i / g.size_y << ", " << i % g.size_y << "): CARMEN " << g.cells[i]
        << ", got " << got.cells[i];
  }
  r << "\n  " << n << " cells differ";
  return r.str();
}

// Maps case `c` with `path` and expects CARMEN's GRIDMAP payload digest.
inline void expect_golden(const Case &c, const Path &path) {
  const std::string log =
      find_log(c.log, {carried_dir(), std::string(VASCO_LOGS_DIR)});
  ASSERT_FALSE(log.empty()) << "no log for " << c.name;
  const LogInput in = load_case(log, carried_dir() + "/params/" + c.params + ".ini");
  const FinishedMap m = path.run(in);
  const std::string got = digest(m);
  EXPECT_EQ(got, c.sha256) << c.name << " through " << path.name << " is not CARMEN's map: "
                           << cell_report(c, m);
}

inline std::string case_label(const Case &c) {
  std::string s = c.name;
  for (char &ch : s)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return s;
}

}  // namespace golden
}  // namespace vasco

#endif  // VASCO_TESTS_GOLDEN_SUPPORT_H
