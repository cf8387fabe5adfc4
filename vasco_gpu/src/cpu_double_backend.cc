// cpu_double: the oracle. DESIGN §2 to the letter: every beam's updates are
// oracle::trace_beam's (the code CARMEN's C API in carmen_egrid_api.cc runs), applied
// in (scan, beam) order with the oracle's arithmetic. Ordinary beams take the
// two-pass form of beam_updates.h (same bytes, about 1.8x faster on fr079:
// the argument is in beam_updates.cc); degenerate ones (a range of -inf) and an
// empty table go through oracle::trace_beam itself. Pass 1 reads no cell, and
// a beam's updates are all applied before the next beam is walked, so every
// cell still sees its updates in (scan, beam) order.
#include <chrono>
#include <optional>
#include <vector>

#include "beam_updates.h"
#include "host_renderer.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/internal/oracle.h"
#include "vasco_gpu/internal/sensor_params.h"
#include "vasco_gpu/internal/table_cache.h"

namespace vasco {
namespace {

// The distance table as egrid.c builds it, with row pointers (none above
// oracle::kMaxBuiltDistanceTable: trace_beam then computes distances); read
// by oracle::trace_beam only.
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

// What a parameter set fixes, built once (a mapping session calls apply()
// for every few scans).
struct Tables {
  DistanceTable distances;
  beam_updates::Evidence evidence;
  explicit Tables(const MapperParams &p)
      : distances(p.table_size(), p.resolution), evidence(sensor_model_of(p), p.resolution, p.table_size()) {}
};

class CpuDoubleRenderer : public HostGridRenderer {
 public:
  CpuDoubleRenderer() : HostGridRenderer("cpu_double", true) {}

  void apply_to(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
                const GridGeometry &geo, float *cells, MapStats *stats) override {
    const auto t0 = std::chrono::steady_clock::now();
    // CARMEN's first update call records the start pose: that is scan 0's
    // (or the given centre's).
    oracle::GridFrame frame = start_frame(geo, batch);
    tables_key_.ensure(params, [&] { tables_.emplace(params); });
    MapStats st;
    beam_updates::BeamUpdates updates(params.table_size());
    for (size_t s = first; s < last; ++s) {
      const oracle::ScanStart start = oracle::scan_start(frame, batch.x[s], batch.y[s], batch.theta[s]);
      oracle::SteppedAngles angle_of{batch.first_angle[s], batch.angle_step[s]};
      const float *range = batch.ranges_of(s);
      double angle = 0;
      for (int i = 0; i < batch.beams_in(s); ++i) {  // oracle::update_scan's loop
        angle_of(i, start.theta, &angle);
        if (!oracle::beam_used(range[i])) {
          ++st.beams_skipped;
          continue;
        }
        ++st.beams_used;
        int x2, y2;
        oracle::beam_end(start, angle, range[i], params.wall_size, frame.resolution, &x2, &y2);
        st.cell_updates += trace(cells, geo, start, x2, y2, range[i], &updates);
      }
    }
    st.scans = last - first;
    st.map_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (stats != nullptr) *stats = st;
  }

 private:
  // One beam's updates, applied; returns how many.
  long trace(float *cells, const GridGeometry &geo, const oracle::ScanStart &s, int x2, int y2, double range,
             beam_updates::BeamUpdates *updates) const {
    const beam_updates::Evidence &evidence = tables_->evidence;
    if (!beam_updates::walkable(evidence.table_size(), s.x1, s.y1, x2, y2)) {
      const DistanceTable &d = tables_->distances;
      return oracle::trace_beam(cells, geo.size_x, geo.size_y, s.x1, s.y1, x2, y2, range, evidence.model(),
                                geo.resolution, d.size(), d.rows());
    }
    beam_updates::collect(evidence, {0, geo.size_x, 0, geo.size_y}, geo.size_y, s.x1, s.y1, x2, y2, range,
                          updates);
    beam_updates::apply(cells, *updates, evidence);
    return updates->count;
  }

  std::optional<Tables> tables_;               // kept between calls
  TableCache tables_key_;  // of tables_
};

}  // namespace

std::unique_ptr<HostGridRenderer> make_cpu_double_renderer() { return std::make_unique<CpuDoubleRenderer>(); }

}  // namespace vasco
