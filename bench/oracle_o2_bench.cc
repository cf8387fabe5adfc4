// oracle_o2_bench — is cpu_double as fast as a plain -O2 build of the same
// loop? This file is compiled with plain -O2 (bench/CMakeLists.txt), so its
// instantiation of the oracle loop (oracle.h) is what a straightforward build
// of CARMEN's routine gives; cpu_double is the library's (Release flags).
// Both run on the bundled fr079 log, alternately, and the grids must be equal.
//
//   oracle_o2_bench [--runs N]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "vasco_gpu/backend.h"
#include "vasco_gpu/renderer.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/internal/oracle.h"
#include "vasco_gpu/internal/sensor_params.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/pipeline/log_scans.h"

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

// The oracle loop, as a plain build compiles it.
std::vector<float> plain_loop(const vasco::ScanBatch &b, const vasco::MapperParams &p,
                              const vasco::GridGeometry &geo) {
  std::vector<float> cells(geo.num_cells(), -1.0f);
  vasco::oracle::GridFrame frame;
  frame.size_x = geo.size_x;
  frame.size_y = geo.size_y;
  frame.resolution = geo.resolution;
  frame.theta_offset = geo.theta_offset;
  const vasco::egrid::SensorModel<double> model = vasco::sensor_model_of(p);
  const int t = p.table_size();
  std::vector<double> table(static_cast<size_t>(t) * t);
  std::vector<const double *> rows(t);
  for (int i = 0; i < t; ++i) {
    rows[i] = table.data() + static_cast<size_t>(i) * t;
    for (int j = 0; j < t; ++j) table[static_cast<size_t>(i) * t + j] = vasco::egrid::cell_distance(i, j, p.resolution);
  }
  for (size_t s = 0; s < b.num_scans(); ++s)
    vasco::oracle::update_scan(cells.data(), frame, model, p.wall_size, t, rows.data(), b.x[s], b.y[s],
                               b.theta[s], b.beams_in(s), b.ranges_of(s),
                               vasco::oracle::SteppedAngles{b.first_angle[s], b.angle_step[s]});
  return cells;
}

}  // namespace

int main(int argc, char **argv) {
  int runs = 5;
  if (argc == 3 && std::strcmp(argv[1], "--runs") == 0) runs = std::max(1, std::atoi(argv[2]));
  const vasco::MapperParams p;
  vasco::LogLoadStats ls;
  const auto batch = vasco::load_scans(std::string(VASCO_SOURCE_DIR) + "/logs/fr079-complete.gfs.log.gz",
                                       p, carmen::LogReaderOptions{}, &ls);
  const auto geo = vasco::size_grid(batch, p);
  auto lib = vasco::make_renderer("cpu_double");
  std::vector<double> t_lib, t_o2;
  bool equal = true;
  for (int r = 0; r < runs + 1; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    const auto a = vasco::render_grid(*lib, batch, p, geo);
    auto t1 = std::chrono::steady_clock::now();
    const auto b = plain_loop(batch, p, geo);
    auto t2 = std::chrono::steady_clock::now();
    equal = equal && a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
    if (r == 0) continue;  // warm-up
    t_lib.push_back(std::chrono::duration<double>(t1 - t0).count());
    t_o2.push_back(std::chrono::duration<double>(t2 - t1).count());
  }
  std::printf("fr079, vasco defaults, median of %d runs (one core):\n", runs);
  std::printf("  cpu_double (library build)   %8.3f s\n", median(t_lib));
  std::printf("  the same loop, plain -O2     %8.3f s\n", median(t_o2));
  std::printf("  ratio cpu_double / plain -O2 %8.3f  (grids %s)\n", median(t_lib) / median(t_o2),
              equal ? "bit-identical" : "DIFFER");
  return equal ? 0 : 1;
}
