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
    for (int i = 0; i < size; ++i) {
      rows_[i] = values_.data() + static_cast<size_t>(i) * n;
      for (int j = 0; j < size; ++j) rows_[i][j] = egrid::cell_distance(i, j, resolution);
    }
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

  std::vector<float> map(const ScanBatch &batch, const MapperParams &params,
                         const GridGeometry &geo, MapStats *stats) override {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<float> cells(geo.num_cells(), egrid::kUnknown);
    oracle::GridFrame frame;
    frame.size_x = geo.size_x;
    frame.size_y = geo.size_y;
    frame.resolution = geo.resolution;
    frame.theta_offset = geo.theta_offset;
    const egrid::ModelParams model{params.p_prior, params.p_occ, params.p_emp, params.range_sure,
                                   params.range_max};
    const DistanceTable table(params.table_size(), params.resolution);
    MapStats st;
    for (size_t s = 0; s < batch.num_scans(); ++s) {
      const auto c = oracle::update_scan(
          cells.data(), frame, model, params.wall_size, table.size(), table.rows(), batch.x[s],
          batch.y[s], batch.theta[s], batch.beams_in(s), batch.ranges_of(s),
          oracle::SteppedAngles{batch.first_angle[s], batch.angle_step[s]});
      st.beams_used += c.beams_used;
      st.beams_skipped += c.beams_skipped;
      st.cell_updates += c.cell_updates;
    }
    st.scans = batch.num_scans();
    st.map_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (stats != nullptr) *stats = st;
    return cells;
  }
};

}  // namespace

std::unique_ptr<Backend> make_cpu_double_backend() { return std::make_unique<CpuDoubleBackend>(); }

}  // namespace vasco
