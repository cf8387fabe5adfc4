// Helpers shared by the tests: bundled logs and running a backend on them.
#ifndef VASCO_TESTS_TEST_SUPPORT_H
#define VASCO_TESTS_TEST_SUPPORT_H

#include <string>
#include <vector>

#include "vasco_gpu/backend.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {
namespace testing_support {

inline std::string bundled_log(const std::string &name) { return std::string(VASCO_LOGS_DIR) + "/" + name; }

struct LoadedLog {
  ScanBatch batch;
  GridGeometry geo;
};

inline LoadedLog load_log(const std::string &path, const MapperParams &params) {
  LoadedLog l;
  LogLoadStats stats;
  l.batch = load_scans(path, params, carmen::LogReaderOptions{}, &stats);
  l.geo = size_grid(l.batch, params);
  return l;
}

inline std::vector<float> run_backend(Backend &backend, const LoadedLog &log,
                                      const MapperParams &params, MapStats *stats = nullptr) {
  return backend.map(log.batch, params, log.geo, stats);
}

}  // namespace testing_support
}  // namespace vasco

#endif  // VASCO_TESTS_TEST_SUPPORT_H
