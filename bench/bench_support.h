// bench_support.h — what the benchmark programs share: the logs and
// parameter sets they measure, a median and the format of a time. (VASCO_SOURCE_DIR
// is defined by bench/CMakeLists.txt.)
#ifndef VASCO_BENCH_SUPPORT_H
#define VASCO_BENCH_SUPPORT_H

#include <algorithm>
#include <chrono>
#include <cstdio>
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

struct Dataset {
  std::string name, path;
};

struct ParamSet {
  std::string name;
  vasco::MapperParams params;
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
  return {{"paper", paper}, {"vasco_default_raw", vasco::MapperParams{}}};
}

}  // namespace bench

#endif  // VASCO_BENCH_SUPPORT_H
