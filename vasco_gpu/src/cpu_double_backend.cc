// cpu_double: the oracle. DESIGN §2 to the letter, through the same code
// (oracle.h) as CARMEN's C API in egrid.cc.
#include <chrono>

#include "vasco_gpu/backend.h"
#include "vasco_gpu/oracle.h"

namespace vasco {
namespace {

// The distance table as egrid.c builds it, with row pointers (none above
// oracle::kMaxBuiltDistanceTable: trace_beam then computes distances).
class DistanceTable {
 public:
  DistanceTable(int size, double resolution) : size_(size) {
    if (size <= 0 || size > oracle::kMaxBuiltDistanceTable) return;
    const size_t n = static_cast<size_t>(size);
    values_.resize(n * n);
    rows_.resize(n);
    for (int i = 0; i < size; ++i) rows_[i] = values_.data() + static_cast<size_t>(i) * n;
    oracle::fill_distance_table(rows_.data(), size, resolution);
  }
  const double *const *rows() const { return rows_.empty() ? nullptr : rows_.data(); }
  int size() const { return size_; }

 private:
  int size_;
  std::vector<double> values_;
  std::vector<double *> rows_;
};

class CpuDoubleBackend : public Backend {
 public:
  std::string name() const override { return "cpu_double"; }

  void apply(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
             const GridGeometry &geo, float *cells, MapStats *stats) override {
    const auto t0 = std::chrono::steady_clock::now();
    oracle::GridFrame frame;
    frame.size_x = geo.size_x;
    frame.size_y = geo.size_y;
    frame.resolution = geo.resolution;
    frame.theta_offset = geo.theta_offset;
    // CARMEN's first update call records the start pose: that is scan 0's.
    if (first > 0 && batch.num_scans() > 0) oracle::scan_start(frame, batch.x[0], batch.y[0], batch.theta[0]);
    const egrid::SensorModel<double> model = params.sensor_model();
    if (table_.size() != params.table_size() || table_resolution_ != params.resolution) {
      table_ = DistanceTable(params.table_size(), params.resolution);
      table_resolution_ = params.resolution;
    }
    MapStats st;
    for (size_t s = first; s < last; ++s) {
      const auto c = oracle::update_scan(
          cells, frame, model, params.wall_size, table_.size(), table_.rows(), batch.x[s],
          batch.y[s], batch.theta[s], batch.beams_in(s), batch.ranges_of(s),
          oracle::SteppedAngles{batch.first_angle[s], batch.angle_step[s]});
      st.beams_used += c.beams_used;
      st.beams_skipped += c.beams_skipped;
      st.cell_updates += c.cell_updates;
    }
    st.scans = last - first;
    st.map_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (stats != nullptr) *stats = st;
  }

 private:
  DistanceTable table_{0, 0.0};  // kept between calls: built once per parameter set
  double table_resolution_ = 0;
};

}  // namespace

std::unique_ptr<Backend> make_cpu_double_backend() { return std::make_unique<CpuDoubleBackend>(); }

}  // namespace vasco
