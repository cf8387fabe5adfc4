// egrid_math.h — the per-cell mathematics of CARMEN 0.7.4's evidence grid
// (vasco/egrid.c), written once and compiled into every backend: the CPU
// oracle, the float CPU port and the CUDA kernels. A CPU test of these
// functions therefore exercises exactly what the GPU runs.
//
// Everything here is a pure function of its arguments. Double versions follow
// CARMEN's C operation by operation (left-to-right evaluation, no fused
// multiply-add: host code is built with -ffp-contract=off and device code with
// --fmad=false), so results are bit-identical wherever they run.
#ifndef VASCO_GPU_EGRID_MATH_H
#define VASCO_GPU_EGRID_MATH_H

#include <climits>
#include <cmath>
#include <cstdint>

#include "carmen_compat/host_device.h"

namespace vasco {
namespace egrid {

// Beams whose float range is not below this are skipped entirely
// (egrid.c's LASER_RANGE_LIMIT): they clear nothing.
constexpr double kLaserRangeLimit = 50.0;
// Whether a beam is used at all: float range promoted to double, below 50 m.
// (NaN and +inf are not; -inf and negative ranges are, as in CARMEN.)
VG_HD bool is_beam_used(float range) { return static_cast<double>(range) < kLaserRangeLimit; }

// Distance used for cells beyond the distance table (egrid.c uses 1e6).
constexpr double kFarDistance = 1e6;
// Cell value meaning "unknown".
constexpr float kUnknown = -1.0f;

// Where cell (x, y) of an x-major grid of columns of size_y cells is:
// x * size_y + y, in 64 bits (a grid may pass 2^31 cells; its sides are
// ints, so the index is below 2^62). Every backend addresses its grid with it.
VG_HD int64_t cell_index(int x, int y, int size_y) {
  return static_cast<int64_t>(x) * static_cast<int64_t>(size_y) + static_cast<int64_t>(y);
}

// ---------------------------------------------------------------------------
// Integer helpers with x86-64 semantics. CARMEN's C relies on them for
// degenerate input (e.g. a range of -inf gives an end cell of INT_MIN, and
// the Bresenham set-up then wraps around); we reproduce them without
// undefined behaviour.
// ---------------------------------------------------------------------------

// (int)v as cvttsd2si computes it: truncation toward zero, and INT_MIN for
// NaN or a value outside the int range.
VG_HD int trunc_to_int(double v) {
  if (!(v > -2147483649.0 && v < 2147483648.0)) return INT_MIN;
  return static_cast<int>(v);
}

// A beam's end cell, (int)(l + k·cos(angle)) per axis with k = (range + wall)
// / resolution, computed with a cosine other than the host libm's (the host
// placement's per-step table, beam_placement.cc; the device's sincos,
// exact_placement.cu) is the oracle's where the coordinate v lies farther
// than placement_tolerance from every integer: both sides' errors are below
// 1e-14 relative, 1e-11 is a 1000x margin. Elsewhere the oracle's own
// beam_end decides.
constexpr double kPlacementTolerance = 1e-11;
VG_HD double placement_tolerance(double lx, double ly, double k) {
  return kPlacementTolerance * (1 + fabs(lx) + fabs(ly) + fabs(k));
}
// Whether v lies farther than tol from every integer; false for NaN and past
// +-2^30 (left to the oracle's checks).
VG_HD bool far_from_integers(double v, double tol) {
  if (!(fabs(v) < 1073741824.0)) return false;
  const double f = fabs(v - static_cast<double>(static_cast<int>(v)));  // in [0, 1)
  return f > tol && f < 1 - tol;
}

VG_HD int wrap_add(int a, int b) {
  return static_cast<int>(static_cast<uint32_t>(a) + static_cast<uint32_t>(b));
}
VG_HD int wrap_sub(int a, int b) {
  return static_cast<int>(static_cast<uint32_t>(a) - static_cast<uint32_t>(b));
}
VG_HD int wrap_mul(int a, int b) {
  return static_cast<int>(static_cast<uint32_t>(a) * static_cast<uint32_t>(b));
}
VG_HD int wrap_neg(int a) { return static_cast<int>(0u - static_cast<uint32_t>(a)); }
// abs() as the machine computes it: abs(INT_MIN) == INT_MIN.
VG_HD int wrap_abs(int a) { return a < 0 ? wrap_neg(a) : a; }

// ---------------------------------------------------------------------------
// CARMEN's Bresenham line (global.c), DESIGN §2.1. Both ends are visited.
// ---------------------------------------------------------------------------
struct BresenhamLine {
  int x, y;        // current point in the swapped/flipped frame
  int x_end;       // major coordinate of the end point (swapped/flipped frame)
  int inc;         // +1 or -1 along the major axis
  int d, incr_e, incr_ne;
  bool steep, flipped;
};

VG_HD void bresenham_init(BresenhamLine &l, int x1, int y1, int x2, int y2) {
  // slope as CARMEN computes it: a zero dx gives +-inf (steep), 0/0 gives NaN
  // (not steep: a single cell).
  const double dx = static_cast<double>(wrap_sub(x2, x1));
  const double dy = static_cast<double>(wrap_sub(y2, y1));
  const double slope = dy / dx;
  l.steep = (slope < 0 ? -slope : slope) > 1.0;
  if (l.steep) {
    int t = x1; x1 = y1; y1 = t;
    t = x2; x2 = y2; y2 = t;
  }
  // CARMEN tests (p2x - p1x) * (p2y - p1y) < 0 with int operands: the
  // product wraps at 32 bits, so for far end points (a range of -inf) its
  // sign is not the sign of the exact product.
  l.flipped = wrap_mul(wrap_sub(x2, x1), wrap_sub(y2, y1)) < 0;
  if (l.flipped) {
    y1 = wrap_neg(y1);
    y2 = wrap_neg(y2);
  }
  l.inc = x2 > x1 ? 1 : -1;
  const int delta_x = wrap_sub(x2, x1);
  const int delta_y = wrap_sub(y2, y1);
  l.incr_e = wrap_mul(wrap_mul(2, delta_y), l.inc);
  l.incr_ne = wrap_mul(wrap_mul(2, wrap_sub(delta_y, delta_x)), l.inc);
  l.d = wrap_mul(wrap_sub(wrap_mul(2, delta_y), delta_x), l.inc);
  l.x = x1;
  l.y = y1;
  l.x_end = x2;
}

// The current cell in grid coordinates (undoing the flip, then the swap).
VG_HD void bresenham_current(const BresenhamLine &l, int *cx, int *cy) {
  const int y = l.flipped ? wrap_neg(l.y) : l.y;
  if (l.steep) {
    *cx = y;
    *cy = l.x;
  } else {
    *cx = l.x;
    *cy = y;
  }
}

// Advances one cell; returns false (and does not move) when the end was the
// current cell.
VG_HD bool bresenham_next(BresenhamLine &l) {
  if (l.x == l.x_end) return false;
  l.x = wrap_add(l.x, l.inc);
  if (l.d < 0 || (l.inc < 0 && l.d <= 0)) {
    l.d = wrap_add(l.d, l.incr_e);
  } else {
    l.d = wrap_add(l.d, l.incr_ne);
    l.y = wrap_add(l.y, l.inc);
  }
  return true;
}

// CARMEN's sequential walk from (x1, y1) towards (x2, y2), written once for
// every walker: the cells of steps k = 0 .. steps - 1 in order, inside the
// grid or not; visit(cx, cy, k) returns false to stop there.
template <class Visit>
VG_HD void walk_line(int x1, int y1, int x2, int y2, int steps, Visit &&visit) {
  BresenhamLine line;
  bresenham_init(line, x1, y1, x2, y2);
  for (int k = 0; k < steps; ++k) {
    int cx, cy;
    bresenham_current(line, &cx, &cy);
    if (!visit(cx, cy, k)) return;
    if (!bresenham_next(line)) return;
  }
}

// The walk of one beam over the cells it can update: steps k < table_size
// (no later cell is ever updated: see oracle::trace_beam), cells inside the
// grid only, with i = |cx - x1| and j = |cy - y1| as CARMEN's int arithmetic
// gives them. visit(cx, cy, i, j) returns false to stop the beam there.
template <class Visit>
VG_HD void walk_beam_cells(int x1, int y1, int x2, int y2, int table_size, int size_x, int size_y,
                           Visit &&visit) {
  walk_line(x1, y1, x2, y2, table_size, [&](int cx, int cy, int) {
    if (cx < 0 || cx >= size_x || cy < 0 || cy >= size_y) return true;
    return static_cast<bool>(visit(cx, cy, wrap_abs(wrap_sub(cx, x1)), wrap_abs(wrap_sub(cy, y1))));
  });
}

// ---------------------------------------------------------------------------
// The same walk in closed form, for one thread per cell. Valid for lines whose
// |dx| and |dy| are below 2^29 (then no intermediate value of the sequential
// walk overflows) and whose dx * dy fits an int (then CARMEN's wrapping flip
// test gives the true sign); is_closed_form_line() says whether a line qualifies. The
// cell at step k (0 <= k <= |major delta|) is the cell the sequential walk
// emits after k calls to bresenham_next.
// ---------------------------------------------------------------------------
struct LineParams {
  int x1, y1;       // start, grid coordinates
  int major_len;    // number of steps: the walk visits major_len + 1 cells
  int a, b;         // |major delta| and |minor delta| in the swapped/flipped frame
  int inc;          // +1 or -1
  bool steep, flipped;
};

VG_HD bool is_closed_form_line(int x1, int y1, int x2, int y2) {
  const int64_t dx = static_cast<int64_t>(x2) - x1;
  const int64_t dy = static_cast<int64_t>(y2) - y1;
  const int64_t lim = int64_t(1) << 29;
  if (!(dx > -lim && dx < lim && dy > -lim && dy < lim)) return false;
  // The closed form assumes the flip that the exact product's sign gives;
  // CARMEN's product wraps at 32 bits, so lines whose |dx * dy| does not fit
  // an int (possible from about 46341 cells per axis) are walked instead.
  const int64_t product = dx * dy;
  return product >= INT_MIN && product <= INT_MAX;
}

VG_HD LineParams line_params(int x1, int y1, int x2, int y2) {
  BresenhamLine l;
  bresenham_init(l, x1, y1, x2, y2);
  LineParams p;
  p.x1 = x1;
  p.y1 = y1;
  p.steep = l.steep;
  p.flipped = l.flipped;
  p.inc = l.inc;
  int minor_end = l.steep ? x2 : y2;  // minor coordinate of the end, swapped/flipped frame
  if (l.flipped) minor_end = -minor_end;
  const int dmaj = l.x_end - l.x;
  const int dmin = minor_end - l.y;
  p.a = dmaj < 0 ? -dmaj : dmaj;
  p.b = dmin < 0 ? -dmin : dmin;
  p.major_len = p.a;
  return p;
}

// Minor offset (in units of inc) after k major steps. The sequential walk
// takes the minor step when D >= 0 going forward and when D > 0 going
// backward; solving its recurrence gives round-half-up resp. round-half-down
// of k*b/a.
VG_HD int line_minor_offset(const LineParams &p, int k) {
  if (p.a == 0) return 0;
  const int64_t num = 2 * static_cast<int64_t>(p.b) * k + p.a - (p.inc < 0 ? 1 : 0);
  return static_cast<int>(num / (2 * static_cast<int64_t>(p.a)));
}

VG_HD void line_cell(const LineParams &p, int k, int *cx, int *cy) {
  const int m = line_minor_offset(p, k);
  const int sx1 = p.steep ? p.y1 : p.x1;      // major start
  int sy1 = p.steep ? p.x1 : p.y1;            // minor start
  if (p.flipped) sy1 = -sy1;
  const int maj = sx1 + p.inc * k;
  int min = sy1 + p.inc * m;
  if (p.flipped) min = -min;
  if (p.steep) {
    *cx = min;
    *cy = maj;
  } else {
    *cx = maj;
    *cy = min;
  }
}

// Inverse: the step at which the line visits cell (cx, cy), or -1 if it does
// not. Cheap (multiplications, no division): used by one-thread-per-cell
// kernels to test whether a beam crosses their cell.
VG_HD int line_step_of_cell(const LineParams &p, int cx, int cy) {
  const int maj = p.steep ? cy : cx;
  int min = p.steep ? cx : cy;
  const int sx1 = p.steep ? p.y1 : p.x1;
  int sy1 = p.steep ? p.x1 : p.y1;
  if (p.flipped) {
    sy1 = -sy1;
    min = -min;
  }
  const int k = (maj - sx1) * p.inc;
  if (k < 0 || k > p.major_len) return -1;
  const int m = (min - sy1) * p.inc;
  if (m < 0) return -1;
  // m == line_minor_offset(p, k)  <=>  2a*m <= num < 2a*(m+1)
  if (p.a == 0) return m == 0 ? k : -1;
  const int64_t num = 2 * static_cast<int64_t>(p.b) * k + p.a - (p.inc < 0 ? 1 : 0);
  const int64_t lo = 2 * static_cast<int64_t>(p.a) * m;
  return (num >= lo && num < lo + 2 * static_cast<int64_t>(p.a)) ? k : -1;
}

// ---------------------------------------------------------------------------
// The sensor model and the odds update (DESIGN §2 step 6).
// ---------------------------------------------------------------------------
// The type itself, in a parameter that should convert rather than deduce.
template <class T>
struct Exactly {
  using type = T;
};

// The sensor model's parameters in the precision of the update that reads
// them: double for CARMEN's update, float for CUDA float mode's kernels.
template <class Real>
struct SensorModel {
  Real prior, occ, emp;  // prior_occ, occ_evidence, emp_evidence
  Real sure, max;        // max_sure_range, max_range
};

// Whether a beam stops at a cell at distance d (sensor_model refuses it):
// it depends on d alone, not on the range.
template <class Real>
VG_HD bool stops_beam(const SensorModel<Real> &m, typename Exactly<Real>::type d) {
  return !(d < m.sure) && !(d < m.max);
}

// The evidence p for a cell at distance d of a beam of range r; returns false
// when the beam stops here (d >= max_range). The same expression in either
// precision, chosen by the model (a float range is promoted exactly).
template <class Real>
VG_HD bool sensor_model(const SensorModel<Real> &m, typename Exactly<Real>::type d,
                        typename Exactly<Real>::type r, Real *p) {
  const Real ev = d < r ? m.emp : m.occ;
  if (d < m.sure) {
    *p = ev;
  } else if (d < m.max) {
    *p = ev + (d - m.sure) / m.max * (m.prior - ev);
  } else {
    return false;
  }
  return true;
}

// The odds factors of an update at distance d, the one source of every
// backend's factor tables: for a cell the beam passes (free, d < range) and
// for the cell it ends in (occupied), odds_factor(prior, p) with p =
// sensor_model(d, +inf) resp. sensor_model(d, -inf). sensor_model uses the
// range only through d < range, so odds_apply(cell, prior, factor) is
// odds_update(cell, prior, sensor_model(d, range)) bit for bit. Returns false
// (zeros) where d >= max_range: the beam stops there.
VG_HD bool odds_factors_at(const SensorModel<double> &m, double d, double *f_free, double *f_occ);

// Distance between two cells i and j cells apart, as the distance table holds it.
VG_HD double cell_distance(int i, int j, double resolution) {
  return sqrt(static_cast<double>(wrap_add(wrap_mul(i, i), wrap_mul(j, j)))) * resolution;
}

// The distance of a cell depends on i and j only through n = i*i + j*j, and
// grows with n (sqrt and the product are monotone). So "distance < limit"
// is exactly "n < first_square_not_below(limit, ...)": the smallest n in
// [0, n_max] whose distance is not below `limit`, or n_max + 1. Valid where
// i*i + j*j does not wrap (tables of at most 2^15 entries per axis).
VG_HD int64_t first_square_not_below(double limit, double resolution, int64_t n_max) {
  int64_t lo = 0, hi = n_max + 1;
  while (lo < hi) {
    const int64_t mid = lo + (hi - lo) / 2;
    if (!(sqrt(static_cast<double>(mid)) * resolution < limit)) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  return lo;
}

// One odds update of a stored cell, exactly as egrid.c evaluates it:
// new = 1 - 1 / (1 + ((1-prior)/prior) * p / (1-p) * old / (1-old)), every step
// in double except `1 - old`, which in CARMEN's C is int minus float: a float
// subtraction. An unknown cell (-1) is first set to (float)prior.
//
// Split in two so that a kernel can compute the part that does not depend on
// the cell ahead of time: odds_factor(prior, p) is the left-to-right product
// ((1-prior)/prior) * p / (1-p) — the same operations in the same order, so
// odds_apply(cell, prior, odds_factor(prior, p)) == odds_update(cell, prior, p)
// bit for bit.
VG_HD double odds_factor(double prior, double p) {
  double t = (1.0 - prior) / prior;
  t = t * p;
  t = t / (1.0 - p);
  return t;
}

VG_HD float odds_apply(float cell, double prior, double factor) {
  if (cell == kUnknown) cell = static_cast<float>(prior);
  double t = factor * static_cast<double>(cell);
  t = t / static_cast<double>(1.0f - cell);
  const double v = 1.0 - 1.0 / (1.0 + t);
  return static_cast<float>(v);
}

VG_HD float odds_update(float cell, double prior, double p) {
  return odds_apply(cell, prior, odds_factor(prior, p));
}

VG_HD bool odds_factors_at(const SensorModel<double> &m, double d, double *f_free, double *f_occ) {
  double p;
  if (!sensor_model(m, d, HUGE_VAL, &p)) {
    *f_free = *f_occ = 0.0;
    return false;
  }
  *f_free = odds_factor(m.prior, p);
  sensor_model(m, d, -HUGE_VAL, &p);
  *f_occ = odds_factor(m.prior, p);
  return true;
}

}  // namespace egrid
}  // namespace vasco

#endif  // VASCO_GPU_EGRID_MATH_H
