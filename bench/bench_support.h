// bench_support.h — what the benchmark programs share: the logs and
// parameter sets they measure, a median and the format of a time. (VASCO_SOURCE_DIR
// is defined by bench/CMakeLists.txt.)
#ifndef VASCO_BENCH_SUPPORT_H
#define VASCO_BENCH_SUPPORT_H

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "vasco_gpu/params.h"

namespace bench {

inline double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

inline double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Seconds as milliseconds for a table: two decimals below 10 ms, one below
// a second, none above; "-" for a time not measured (0 or less).
inline std::string ms(double s) {
  char b[32];
  if (s <= 0) return "-";
  if (s < 0.01) std::snprintf(b, sizeof b, "%.2f", s * 1e3);
  else if (s < 1) std::snprintf(b, sizeof b, "%.1f", s * 1e3);
  else std::snprintf(b, sizeof b, "%.0f", s * 1e3);
  return b;
}

// The directory of this program (where log2map is built beside it).
inline std::string self_dir(const char *argv0) {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  std::string p = n > 0 ? std::string(buf, static_cast<size_t>(n)) : std::string(argv0);
  const size_t s = p.find_last_of('/');
  return s == std::string::npos ? "." : p.substr(0, s);
}

// `path` for a shell command line: inside single quotes, each ' as '\''.
inline std::string shell_quoted(const std::string &path) {
  std::string q = "'";
  for (char c : path) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// A temporary .map.gz path of this process, for a run's output.
inline std::string temp_map_path() {
  const char *tmp = std::getenv("TMPDIR");
  return std::string(tmp ? tmp : "/tmp") + "/vasco_bench_" + std::to_string(getpid()) + ".map.gz";
}

struct Dataset {
  std::string name, path;
};

struct ParamSet {
  std::string name;
  vasco::MapperParams params;
  std::string log2map_args;  // the same parameters as log2map options
};

// The logs measured, fr079 first (mapping_bench's end-to-end section uses it).
inline std::vector<Dataset> bench_datasets() {
  const std::string src = VASCO_SOURCE_DIR;
  return {{"fr079", src + "/logs/fr079-complete.gfs.log.gz"}, {"fr101", src + "/logs/fr101.carmen.log.gz"}};
}

// The parameter sets measured on every log.
inline std::vector<ParamSet> bench_param_sets() {
  vasco::MapperParams paper;
  paper.range_max = 6.4;  // the paper's setting, at vasco's 2.5 cm cells
  return {{"paper", paper, "--vasco_range_max 6.4"}, {"vasco_default_raw", vasco::MapperParams{}, ""}};
}

}  // namespace bench

#endif  // VASCO_BENCH_SUPPORT_H
