// beam_updates.cc — a beam's updates in two passes (beam_updates.h).
//
// Why these are oracle::trace_beam's updates, bit for bit.
//  * Which cells. For a closed-form line (egrid::is_closed_form_line) the
//    oracle's cell after k steps is egrid::line_cell(p, k): the major
//    coordinate moved by k, the minor one by m = line_minor_offset(p, k) =
//    floor((2bk + a - [inc < 0]) / 2a) (egrid_math.h; cpu_threads and the
//    CUDA exact mode rest on the same closed form). The walker keeps that
//    floor's remainder, which grows by 2b <= 2a a step, so m grows by 0 or 1.
//    The oracle visits steps k <= k_max = min(a, T - 1) and updates the cells
//    in the grid up to the stop. x and y move monotonically, so the steps
//    whose cell lies in a box (the grid, or a stripe of it) are one run
//    k_begin .. k_end, found in closed form: the major coordinate moves by
//    one a step, and m >= M first holds at k = ceil((2aM - a + [inc < 0]) / 2b).
//  * The distance. i = |cx - x1| and j = |cy - y1| are k and m (in some
//    order), both <= k < T, so the oracle's distance is the table's
//    d(n) = sqrt((double)n) * resolution, n = k*k + m*m (no wrap: T <= 32767).
//  * The evidence. d(n) never decreases with n (correctly rounded sqrt and
//    product are monotone), so each comparison sensor_model makes — d < sure,
//    d < max, d < range — is n < the first n whose d is not below the limit
//    (egrid::first_square_not_below, found by bisection or, for the range,
//    by stepping from an estimate: the same n). Below sure, p is emp or occ
//    and the factor odds_factor(prior, p): computed once with the same
//    operations. From sure to the stop it is odds_factors_at(model, d(n)),
//    as cpu_threads and the CUDA exact mode tabulate it (egrid_math.h: the
//    same bits as sensor_model then odds_factor), or computed per cell.
//  * The stop. The oracle stops at the first cell in the grid whose n is
//    >= n_stop = max(n_sure, n_max); n only grows along the walk, so every
//    later cell would stop too, and a box's run may break at its first such
//    cell, whether or not an earlier cell outside the box stopped.
//  * The update. Within a beam every cell is visited once (the major
//    coordinate strictly moves), so its updates commute: pass 2 may do four
//    at a time. It performs egrid::odds_apply's operations lane by lane:
//    unknown -> (float)prior, factor * (double)cell, / (double)(1.0f - cell),
//    1 - 1 / (1 + t), (float). Vector IEEE operations round exactly as scalar
//    ones (same MXCSR), and -ffp-contract=off leaves them unfused.
#include "beam_updates.h"

#include <algorithm>
#include <cmath>

namespace vasco {
namespace beam_updates {
namespace {

// The most factor pairs tabulated beyond sure (16 bytes each: 1.9 MB at
// vasco's defaults); longer tables are computed per cell instead.
constexpr int64_t kMaxTabulated = int64_t(1) << 18;
// The steps of a closed-form line whose cell lies in a box, walked in order
// (see the top of the file).
class Walker {
 public:
  Walker(const egrid::LineParams &p, int k_max, const Box &box, int size_y);

  int walked() const { return static_cast<int>(k_ - k_begin_); }

  // Walks on while the cell's n = k*k + m*m is below `limit`; visit(position
  // in the run, grid index, n) for each cell.
  template <class Visit>
  void walk_below(int64_t limit, Visit &&visit) {
    for (; k_ <= k_end_; step()) {
      const int64_t n = k_ * k_ + m_ * m_;
      if (n >= limit) return;
      visit(walked(), index_, n);
    }
  }

 private:
  // Whether the minor coordinate moves is written as a select; GCC makes it
  // a branch, which measured faster on fr079 than a branch-free mask (the
  // remainder's update is the loop's critical path).
  void step() {
    const int64_t stay = rem_ + two_b_, move = rem_ + two_b_ - two_a_;
    const bool moves = move >= 0;
    rem_ = moves ? move : stay;
    m_ += moves;
    index_ += moves ? diagonal_step_ : major_step_;
    ++k_;
  }

  int64_t two_a_, two_b_, a_minus_c_;  // 2a, 2b, a - [inc < 0]
  int64_t k_begin_, k_end_, k_, m_;
  int64_t rem_;                         // 2bk + a - [inc < 0] - 2am, in [0, 2a)
  int64_t index_, major_step_, diagonal_step_;
};

Walker::Walker(const egrid::LineParams &p, int k_max, const Box &box, int size_y)
    : two_a_(2 * static_cast<int64_t>(p.a)), two_b_(2 * static_cast<int64_t>(p.b)),
      a_minus_c_(p.a - (p.inc < 0 ? 1 : 0)) {
  const int minor_sign = p.flipped ? -p.inc : p.inc;
  int64_t k_lo, k_hi;
  steps_in_box(p, k_max, box, &k_lo, &k_hi);
  k_begin_ = k_ = k_lo;
  k_end_ = k_hi;
  // The walk's state after k_lo steps (k_lo <= k_max < 2^15).
  m_ = egrid::line_minor_offset(p, static_cast<int>(k_lo));
  rem_ = two_b_ * k_ + a_minus_c_ - two_a_ * m_;
  int cx, cy;
  egrid::line_cell(p, static_cast<int>(k_lo), &cx, &cy);
  index_ = egrid::cell_index(cx, cy, size_y);
  major_step_ = p.steep ? p.inc : static_cast<int64_t>(p.inc) * size_y;
  diagonal_step_ = major_step_ + (p.steep ? static_cast<int64_t>(minor_sign) * size_y : minor_sign);
}

// Four lanes of pass 2: GCC/Clang vector extensions, lowered to SSE2 (two
// doubles per division) on any x86-64.
typedef double Double4 __attribute__((vector_size(32)));
typedef float Float4 __attribute__((vector_size(16)));
typedef int32_t Int4 __attribute__((vector_size(16)));

// egrid::odds_apply on four cells, operation for operation.
// (The factor by reference: a 32-byte vector by value would change the ABI
// without AVX, which clang warns about.)
Float4 odds_apply4(Float4 cell, float prior, const Double4 &factor) {
  const Float4 unknown = {egrid::kUnknown, egrid::kUnknown, egrid::kUnknown, egrid::kUnknown};
  const Float4 prior4 = {prior, prior, prior, prior};
  const Float4 one_f = {1.0f, 1.0f, 1.0f, 1.0f};
  const Double4 one = {1.0, 1.0, 1.0, 1.0};
  const Int4 is_unknown = cell == unknown;
  cell = reinterpret_cast<Float4>((reinterpret_cast<Int4>(prior4) & is_unknown) |
                                  (reinterpret_cast<Int4>(cell) & ~is_unknown));
  Double4 t = factor * __builtin_convertvector(cell, Double4);
  t = t / __builtin_convertvector(one_f - cell, Double4);
  return __builtin_convertvector(one - one / (one + t), Float4);
}

// Updates the distinct cells index[0, n) with factors factor_at(k).
template <class FactorAt>
void apply_run(float *cells, const int64_t *index, int n, double prior, FactorAt &&factor_at) {
  int k = 0;
  for (; k + 4 <= n; k += 4) {
    const Float4 cell = {cells[index[k]], cells[index[k + 1]], cells[index[k + 2]], cells[index[k + 3]]};
    const Double4 f = {factor_at(k), factor_at(k + 1), factor_at(k + 2), factor_at(k + 3)};
    const Float4 v = odds_apply4(cell, static_cast<float>(prior), f);
    for (int l = 0; l < 4; ++l) cells[index[k + l]] = v[l];
  }
  for (; k < n; ++k) cells[index[k]] = egrid::odds_apply(cells[index[k]], prior, factor_at(k));
}

}  // namespace

// egrid::first_square_not_below(limit, resolution, n_max), stepping from an
// estimate instead of bisecting (it is needed once per beam, where 20 square
// roots would cost as much as the walk). The same n: d is monotone, and the
// loops end where d(n - 1) < limit <= d(n).
int64_t first_square_near(double limit, double resolution, int64_t n_max) {
  if (!(limit > 0)) return 0;  // d(0) = 0 is not below it
  auto below = [&](int64_t n) { return std::sqrt(static_cast<double>(n)) * resolution < limit; };
  const double cells = limit / resolution;
  const double guess = cells * cells;
  int64_t n = guess >= static_cast<double>(n_max) ? n_max + 1 : static_cast<int64_t>(guess);
  while (n > 0 && !below(n - 1)) --n;
  while (n <= n_max && below(n)) ++n;
  return n;
}

void steps_in_box(const egrid::LineParams &p, int k_max, const Box &box, int64_t *k_first, int64_t *k_last) {
  const int64_t two_a = 2 * static_cast<int64_t>(p.a), two_b = 2 * static_cast<int64_t>(p.b);
  const int64_t a_minus_c = p.a - (p.inc < 0 ? 1 : 0);
  // The first step k whose minor offset line_minor_offset(p, k) is >= m.
  auto first_step_with_offset = [&](int64_t m) -> int64_t {
    if (m <= 0) return 0;
    if (two_b == 0) return int64_t(1) << 62;  // never
    return (two_a * m - a_minus_c + two_b - 1) / two_b;
  };
  const int64_t major = p.steep ? p.y1 : p.x1, minor = p.steep ? p.x1 : p.y1;
  const int64_t major_lo = p.steep ? box.y_lo : box.x_lo, major_hi = p.steep ? box.y_hi : box.x_hi;
  const int64_t minor_lo = p.steep ? box.x_lo : box.y_lo, minor_hi = p.steep ? box.x_hi : box.y_hi;
  const int minor_sign = p.flipped ? -p.inc : p.inc;
  // Steps whose major coordinate, major + inc * k, is in the box ...
  int64_t k_lo = p.inc > 0 ? major_lo - major : major - (major_hi - 1);
  int64_t k_hi = p.inc > 0 ? major_hi - 1 - major : major - major_lo;
  // ... and whose minor offset m puts minor + minor_sign * m in the box.
  // m(k) <= k (b <= a), so a bound m_hi >= k_max limits nothing: a beam that
  // stays inside the box needs no division here.
  const int64_t m_lo = minor_sign > 0 ? minor_lo - minor : minor - (minor_hi - 1);
  const int64_t m_hi = minor_sign > 0 ? minor_hi - 1 - minor : minor - minor_lo;
  k_lo = std::max({k_lo, int64_t(0), first_step_with_offset(m_lo)});
  k_hi = std::min({k_hi, static_cast<int64_t>(k_max), m_hi >= k_max ? k_max : first_step_with_offset(m_hi + 1) - 1});
  if (k_lo > k_hi) k_lo = 0, k_hi = -1;  // no cell in the box
  *k_first = k_lo;
  *k_last = k_hi;
}

Evidence::Evidence(const egrid::SensorModel<double> &model, double resolution, int table_size)
    : model_(model), resolution_(resolution), table_size_(table_size) {
  n_top_ = table_size > 0 ? 2 * static_cast<int64_t>(table_size - 1) * (table_size - 1) : 0;
  n_sure_ = egrid::first_square_not_below(model.sure, resolution, n_top_);
  n_stop_ = std::max(n_sure_, egrid::first_square_not_below(model.max, resolution, n_top_));
  f_free_ = egrid::odds_factor(model.prior, model.emp);  // sensor_model's p below sure
  f_occ_ = egrid::odds_factor(model.prior, model.occ);
  if (n_stop_ - n_sure_ > kMaxTabulated) return;
  beyond_sure_.resize(static_cast<size_t>(n_stop_ - n_sure_));
  for (int64_t n = n_sure_; n < n_stop_; ++n) {
    Pair &e = beyond_sure_[static_cast<size_t>(n - n_sure_)];
    egrid::odds_factors_at(model, std::sqrt(static_cast<double>(n)) * resolution, &e.f_free, &e.f_occ);
  }
}

int64_t Evidence::range_square(double range) const { return first_square_near(range, resolution_, n_top_); }

double Evidence::computed_factor(int64_t n, double range) const {
  double p = 0;  // set: below the stop, sensor_model does not refuse
  egrid::sensor_model(model_, std::sqrt(static_cast<double>(n)) * resolution_, range, &p);
  return egrid::odds_factor(model_.prior, p);
}

BeamUpdates::BeamUpdates(int table_size)
    : index(static_cast<size_t>(std::max(table_size, 1))), factor(index.size()) {}

bool walkable(int table_size, int x1, int y1, int x2, int y2) {
  return table_size > 0 && egrid::is_closed_form_line(x1, y1, x2, y2);
}

void collect(const Evidence &evidence, const Box &box, int size_y, int x1, int y1, int x2, int y2,
             double range, BeamUpdates *out) {
  const egrid::LineParams p = egrid::line_params(x1, y1, x2, y2);
  Walker w(p, std::min(p.major_len, evidence.table_size() - 1), box, size_y);
  const int64_t n_range = evidence.range_square(range);
  int64_t *__restrict index = out->index.data();
  double *__restrict factor = out->factor.data();
  // n never decreases along the walk: each zone of the evidence is a run.
  auto record = [&](int k, int64_t i, int64_t) { index[k] = i; };
  w.walk_below(std::min(n_range, evidence.sure_square()), record);
  out->n_free = w.walked();
  w.walk_below(evidence.sure_square(), record);
  out->n_const = w.walked();
  w.walk_below(evidence.stop_square(), [&](int k, int64_t i, int64_t n) {
    index[k] = i;
    factor[k] = evidence.factor_beyond_sure(n, n_range, range);
  });
  out->count = w.walked();
}

void apply(float *cells, const BeamUpdates &updates, const Evidence &evidence) {
  const double prior = evidence.model().prior;
  const double f_free = evidence.free_factor(), f_occ = evidence.occupied_factor();
  const int64_t *index = updates.index.data();
  const double *factor = updates.factor.data() + updates.n_const;
  apply_run(cells, index, updates.n_free, prior, [&](int) { return f_free; });
  apply_run(cells, index + updates.n_free, updates.n_const - updates.n_free, prior, [&](int) { return f_occ; });
  apply_run(cells, index + updates.n_const, updates.count - updates.n_const, prior,
            [&](int k) { return factor[k]; });
}

}  // namespace beam_updates
}  // namespace vasco
