// beam_updates.h — the oracle's updates of one beam in two passes, for the
// exact CPU backends (cpu_double, and cpu_threads per stripe): pass 1 walks
// the beam and collects its cells and odds factors, pass 2 applies the odds
// updates four cells at a time. Same bytes as oracle::trace_beam; the
// argument is at the top of beam_updates.cc.
//
// Why two passes. perf on fr079 puts about half of the oracle's ~7 ns per
// update on odds_update's chain of three divisions: t / (1 - p) for the
// evidence, then t / (1 - cell) and 1 / (1 + t) for the cell. A per-(i, j)
// table of the evidence's factor (cpu_threads' former choice) removes the
// first, but its 32-byte entries (5 MB at vasco's defaults) miss the cache
// at every cell, so it gained nothing. Here the factor is a constant below
// range_sure and an entry of a table indexed by the squared cell distance
// beyond it (1.9 MB, reached by a tenth of the updates), and the cell's two
// divisions of a whole beam, independent of each other (a beam visits a
// cell once), go two doubles per instruction: about 1.8x on fr079.
#ifndef VASCO_GPU_SRC_BEAM_UPDATES_H
#define VASCO_GPU_SRC_BEAM_UPDATES_H

#include <cstdint>
#include <vector>

#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace beam_updates {

// The sensor model by squared cell distance n = i*i + j*j, for one parameter
// set: where its evidence is constant, where it changes with the distance,
// where the beam stops.
class Evidence {
 public:
  Evidence(const egrid::SensorModel<double> &model, double resolution, int table_size);

  const egrid::SensorModel<double> &model() const { return model_; }
  int table_size() const { return table_size_; }
  // The first n whose distance is not below the beam's range.
  int64_t range_square(double range) const;
  int64_t sure_square() const { return n_sure_; }  // below: constant evidence
  int64_t stop_square() const { return n_stop_; }  // from here on: the beam stops
  double free_factor() const { return f_free_; }   // odds factors below sure
  double occupied_factor() const { return f_occ_; }
  // The odds factor at n, sure_square() <= n < stop_square(), for a beam
  // whose range_square is n_range.
  double factor_beyond_sure(int64_t n, int64_t n_range, double range) const {
    if (beyond_sure_.empty()) return computed_factor(n, range);
    const Pair &e = beyond_sure_[static_cast<size_t>(n - n_sure_)];
    return n < n_range ? e.f_free : e.f_occ;
  }

 private:
  double computed_factor(int64_t n, double range) const;

  struct Pair {
    double f_free, f_occ;
  };
  egrid::SensorModel<double> model_;
  double resolution_;
  int table_size_;
  int64_t n_top_, n_sure_, n_stop_;
  double f_free_, f_occ_;
  std::vector<Pair> beyond_sure_;  // egrid::odds_factors_at(d(n)) from n_sure_, when small
};

// A beam's updates, in walk order: cells index[0, n_free) get the free
// factor, [n_free, n_const) the occupied one, and k in [n_const, count)
// factor[k].
struct BeamUpdates {
  std::vector<int64_t> index;  // x * size_y + y
  std::vector<double> factor;
  int n_free = 0, n_const = 0, count = 0;
  // Room for the longest walk: table_size steps.
  explicit BeamUpdates(int table_size);
};

// Cells [x_lo, x_hi) x [y_lo, y_hi), inside the grid (empty: all 0).
struct Box {
  int x_lo = 0, x_hi = 0, y_lo = 0, y_hi = 0;
  int width() const { return x_hi - x_lo; }
  int height() const { return y_hi - y_lo; }
  size_t cells() const { return static_cast<size_t>(width()) * static_cast<size_t>(height()); }
};

// egrid::first_square_not_below(limit, resolution, n_max), stepping from an
// estimate instead of bisecting (it is needed once per beam, where 20 square
// roots would cost as much as the walk). The same n.
int64_t first_square_near(double limit, double resolution, int64_t n_max);

// The steps k of a closed-form line whose cell lies in `box`, k <= k_max:
// one run [*k_first, *k_last] (x and y move monotonically), empty as
// [0, -1]. Shared by the exact backends' walker and cpu_float's.
void steps_in_box(const egrid::LineParams &p, int k_max, const Box &box, int64_t *k_first, int64_t *k_last);

// Whether collect() can walk the line (x1, y1) -> (x2, y2): a closed-form
// line (egrid::is_closed_form_line) and steps to walk. Other beams go through
// oracle::trace_beam.
bool walkable(int table_size, int x1, int y1, int x2, int y2);

// Pass 1: of the oracle's updates of a walkable beam, those whose cell lies in
// `box`, into `out`; size_y is the grid's.
void collect(const Evidence &evidence, const Box &box, int size_y, int x1, int y1, int x2, int y2,
             double range, BeamUpdates *out);

// Pass 2: applies them to `cells`.
void apply(float *cells, const BeamUpdates &updates, const Evidence &evidence);

}  // namespace beam_updates
}  // namespace vasco

#endif  // VASCO_GPU_SRC_BEAM_UPDATES_H
