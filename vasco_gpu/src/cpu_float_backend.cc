// cpu_float: the paper's CPU port — the oracle's loops in single precision
// (float pose arithmetic and trig, a float distance table, the float odds
// update). Measured against the oracle, never promised equal to it.
#include <chrono>
#include <cmath>

#include "vasco_gpu/backend.h"
#include "vasco_gpu/egrid_math.h"
#include "vasco_gpu/oracle.h"

namespace vasco {
namespace {

class CpuFloatBackend : public Backend {
 public:
  std::string name() const override { return "cpu_float"; }

  void apply(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
             const GridGeometry &geo, float *cells, MapStats *stats) override {
    const auto t0 = std::chrono::steady_clock::now();
    const int sx = geo.size_x, sy = geo.size_y;
    const float res = static_cast<float>(params.resolution);
    const float wall = static_cast<float>(params.wall_size);
    const egrid::SensorModel<float> model = params.sensor_model<float>();
    const int table_size = params.table_size();
    // A float distance table, as the paper's port has, unless it would be huge
    // (then the same sqrtf on the fly).
    const bool tabulated = table_size <= oracle::kMaxBuiltDistanceTable;
    std::vector<float> table(tabulated ? static_cast<size_t>(table_size) * table_size : 0);
    for (int i = 0; i < (tabulated ? table_size : 0); ++i)
      for (int j = 0; j < table_size; ++j)
        table[static_cast<size_t>(i) * table_size + j] =
            std::sqrt(static_cast<float>(i * i + j * j)) * res;

    MapStats st;
    st.scans = last - first;
    if (first >= last) {
      if (stats != nullptr) *stats = st;
      return;
    }
    const float start_x = static_cast<float>(batch.x[0]) / res;
    const float start_y = static_cast<float>(batch.y[0]) / res;
    const float c = static_cast<float>(geo.theta_offset) - static_cast<float>(batch.theta[0]);
    const float cos_c = std::cos(c), sin_c = std::sin(c);
    for (size_t s = first; s < last; ++s) {
      const float px = static_cast<float>(batch.x[s]), py = static_cast<float>(batch.y[s]);
      const float xr = px * cos_c - py * sin_c;
      const float yr = px * sin_c + py * cos_c;
      const float lx = sx / 2.0f + (xr / res - start_x);
      const float ly = sy / 2.0f + (yr / res - start_y);
      const int x1 = egrid::trunc_to_int(std::floor(lx));
      const int y1 = egrid::trunc_to_int(std::floor(ly));
      float angle = static_cast<float>(batch.theta[s]) + c + static_cast<float>(batch.first_angle[s]);
      const float step = static_cast<float>(batch.angle_step[s]);
      const float *range = batch.ranges_of(s);
      const int n = batch.beams_in(s);
      for (int b = 0; b < n; ++b, angle += step) {
        const float r = range[b];
        if (!(r < 50.0f)) {
          ++st.beams_skipped;
          continue;
        }
        ++st.beams_used;
        const int x2 = egrid::trunc_to_int(lx + (r + wall) * std::cos(angle) / res);
        const int y2 = egrid::trunc_to_int(ly + (r + wall) * std::sin(angle) / res);
        // The oracle's walk; the distance and the update in single precision.
        egrid::walk_beam_cells(x1, y1, x2, y2, table_size, sx, sy, [&](int cx, int cy, int i, int j) {
          const float d = (i >= table_size || j >= table_size || i < 0 || j < 0)
                              ? static_cast<float>(egrid::kFarDistance)
                          : tabulated ? table[static_cast<size_t>(i) * table_size + j]
                                      : std::sqrt(static_cast<float>(i * i + j * j)) * res;
          float p;
          if (!egrid::sensor_model(model, d, r, &p)) return false;
          float &cell = cells[static_cast<size_t>(cx) * sy + cy];
          cell = egrid::odds_update_f(cell, model.prior, p);
          ++st.cell_updates;
          return true;
        });
      }
    }
    st.map_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (stats != nullptr) *stats = st;
  }
};

}  // namespace

std::unique_ptr<Backend> make_cpu_float_backend() { return std::make_unique<CpuFloatBackend>(); }

}  // namespace vasco
