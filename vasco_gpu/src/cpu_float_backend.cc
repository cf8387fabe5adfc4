// cpu_float: the fast single-core backend — the oracle's beams and cells,
// evidence as float log-odds increments from a table, summed in float.
// Measured against the oracle (DESIGN §4), never promised equal to it.
//
// Where the time goes in the oracle: per cell update, a sensor model (one
// division), an odds factor (two) and the odds update (two more), all in
// double. Here an update is a table load and an add:
//  * Geometry is the oracle's: beam end cells from place_beams (the oracle's
//    own code), the closed-form walk (egrid_math.h LineParams), and the
//    free / occupied / stop decisions in double exactly as the oracle makes
//    them. So cpu_float updates exactly the cells cpu_double updates.
//  * Along a walk, i = |cx - x1| and j = |cy - y1| never decrease (see
//    cpu_threads_backend.cc), so n = i*i + j*j never decreases, and the
//    oracle's decisions depend on the cell only through d = sqrt(n) * res:
//    free iff n < n_free(range), stop iff n >= n_stop. Both limits are found
//    once per beam; the evidence is a table over (i, j) of log-odds
//    increments logit(p) - logit(prior), rounded to float, for a free and for
//    an occupied cell.
//  * The odds update multiplies odds, so a cell's updates add in log-odds.
//    They are summed per call in floats over the box the call's scans can
//    reach, then each touched cell is converted once: in a scratch where the
//    grid holds an earlier map, in the grid's own cells where it was just
//    reset (a full render: no scratch, each cell written twice). Float, not
//    double: half the bytes to touch for the first time in a fresh process
//    (fr079: 12 MB, not 25) and to keep in cache (fr101 at vasco's defaults:
//    26 MB, inside a 32 MB L3; double's 51 MB was not), which log2map's map
//    phase measured 6-9 % faster (docs/performance.md, History). The sum's
//    rounding, at most n u |S| for a cell of n updates (u = 2^-24, |S| the
//    largest partial sum, at most n times the largest increment), stays
//    below one increment while n < 2^12 updates of the cell in one call.
// What this changes against the oracle: increments rounded to float, their
// sum rounded to float, one rounding of the probability per call instead of
// one per update, and a cell the oracle pins at exactly 1.0 (or 0.0) can come
// back (as in the CUDA float mode). A map built in several calls rounds its
// probabilities and sums once per call: the same bytes for the same calls,
// not the bytes of one call.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "beam_updates.h"
#include "host_renderer.h"
#include "huge_pages.h"
#include "vasco_gpu/internal/beam_placement.h"
#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/internal/log_odds.h"
#include "vasco_gpu/internal/sensor_params.h"
#include "vasco_gpu/internal/table_cache.h"

namespace vasco {
namespace {

#if defined(__FAST_MATH__)
#error "cpu_float's never-updated mark is -0.0: it needs signed zeros (no -ffast-math)"
#endif

// The sums' "never updated" mark: -0.0. Every increment is normalized
// to never be -0.0 (x + 0.0f turns -0.0 into +0.0), and in round-to-nearest
// a sum with a term other than -0.0 is never -0.0 (x + (-x) is +0.0), so a
// touched cell can never hold it.
using Sum = float;
constexpr uint32_t kUntouchedBits = uint32_t(1) << 31;
const Sum kUntouched = -0.0f;

bool untouched(Sum v) {
  uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits == kUntouchedBits;
}

// The evidence of an update: log-odds increments logit(p) - logit(prior) of
// a free and of an occupied cell, by the cell's offsets (i, j) from the
// start, and the limits of the oracle's decisions in n = i*i + j*j.
class EvidenceTable {
 public:
  // Tables past this many (i, j) entries (8 bytes each) are not built: the
  // walks then compute increments per update (only absurd range_max /
  // resolution reach it).
  static constexpr int64_t kMaxEntries = int64_t(1) << 21;

  explicit EvidenceTable(const MapperParams &params)
      : model_(sensor_model_of(params)),
        res_(params.resolution),
        logit_prior_(logit(model_.prior)),
        size_(params.table_size()) {
    const int64_t t = size_;
    // n of a cell of the walk is at most 2 (t - 1)^2: steps k < table_size.
    const int64_t n_max = t > 0 ? 2 * (t - 1) * (t - 1) : 0;
    n_stop_ = egrid::first_square_not_below(std::max(model_.sure, model_.max), res_, n_max);
    n_sure_ = std::min(egrid::first_square_not_below(model_.sure, res_, n_max), n_stop_);
    inv_res_ = 1.0 / res_;
    root_sure_ = std::sqrt(static_cast<double>(n_sure_));
    root_stop_ = std::sqrt(static_cast<double>(n_stop_));
    free_near_ = increment(0, true);
    occ_near_ = increment(0, false);
    if (t <= 0 || t * t > kMaxEntries) return;
    free_.assign(static_cast<size_t>(t * t), 0.0f);
    occ_.assign(static_cast<size_t>(t * t), 0.0f);
    // Row j (the minor offset), column i (the major one): a walk reads a
    // row left to right and moves down a row at a minor step. j <= i.
    for (int64_t j = 0; j < t; ++j)
      for (int64_t i = j; i < t && i * i + j * j < n_stop_; ++i) {
        const size_t e = static_cast<size_t>(j * t + i);
        free_[e] = increment(i * i + j * j, true);
        occ_[e] = increment(i * i + j * j, false);
      }
  }

  int size() const { return size_; }
  int64_t n_stop() const { return n_stop_; }
  // Below n_sure (distance below range_sure) the evidence is a constant:
  // sensor_model gives emp or occ whatever the distance.
  int64_t n_sure() const { return n_sure_; }
  float near_increment(bool free) const { return free ? free_near_ : occ_near_; }
  bool tabulated() const { return !free_.empty(); }
  // The increments at (major offset i, minor offset j) are column[j * size + i].
  const float *column(bool free) const { return free ? free_.data() : occ_.data(); }

  // The smallest n whose distance is not below `range` (at most n_stop):
  // the oracle's free test d < range is n < n_free(range).
  int64_t n_free(double range) const { return beam_updates::first_square_near(range, res_, n_stop_ - 1); }
  // The same test at one n (first_square_near's, so n_free's).
  bool closer_than(int64_t n, double range) const { return std::sqrt(static_cast<double>(n)) * res_ < range; }
  // Estimates: sqrt(n_sure), sqrt(n_stop), and a distance in cells.
  double root_sure() const { return root_sure_; }
  double root_stop() const { return root_stop_; }
  double cells(double distance) const { return distance * inv_res_; }

  // The increment at n < n_stop, computed.
  float increment(int64_t n, bool free) const {
    double p = model_.prior;  // n < n_stop: never refused
    egrid::sensor_model(model_, distance(n), free ? HUGE_VAL : -HUGE_VAL, &p);
    // |x| > 64 saturates a float probability anyway; the clamp keeps an
    // evidence of exactly 0 or 1 a finite increment (no inf - inf later).
    const double x = std::clamp(logit(p) - logit_prior_, -64.0, 64.0);
    return static_cast<float>(x) + 0.0f;
  }

  double logit_prior() const { return logit_prior_; }

 private:
  double distance(int64_t n) const { return std::sqrt(static_cast<double>(n)) * res_; }

  egrid::SensorModel<double> model_;
  double res_, logit_prior_;
  int size_;
  int64_t n_stop_ = 0, n_sure_ = 0;
  double root_sure_ = 0, root_stop_ = 0, inv_res_ = 0;
  float free_near_ = 0, occ_near_ = 0;
  std::vector<float> free_, occ_;
};

// The cells a call's scans can reach. A beam's updated cells lie within
// min(max(|dx|, |dy|), table_size - 1) steps of its scan's start cell (the
// walk stops at its end cell and before table_size steps; a step moves each
// coordinate by at most one). The box from the start cells alone, widened by
// table_size - 1, is a pass over the scans; the one from every beam's own
// reach is tighter but a pass over the beams (2-3 % of a full render), worth
// it only where the start box is large next to the beams (a few scans
// inserted: clearing and merging the box would cost more than the pass).
using beam_updates::Box;

// Where a call's sums go: the cells of `box`, cell (x, y) at
// base[(x - box.x_lo) * stride + (y - box.y_lo)]. The scratch (stride the
// box's height) where the grid holds an earlier map, or the grid itself
// (stride size_y) where it was just reset: its cells in the box start as
// the "never updated" mark and are turned into probabilities in place.
struct SumTarget {
  Sum *base;
  ptrdiff_t stride;
  Box box;
};

Box clipped_box(int64_t x0, int64_t x1, int64_t y0, int64_t y1, const GridGeometry &geo) {
  Box b;
  x0 = std::max<int64_t>(x0, 0), y0 = std::max<int64_t>(y0, 0);
  x1 = std::min<int64_t>(x1, geo.size_x - 1), y1 = std::min<int64_t>(y1, geo.size_y - 1);
  if (x0 > x1 || y0 > y1) return b;
  b.x_lo = static_cast<int>(x0), b.y_lo = static_cast<int>(y0);
  b.x_hi = static_cast<int>(x1 + 1), b.y_hi = static_cast<int>(y1 + 1);
  return b;
}

// How far from its start cell, along either axis, scan s can update a cell:
// its longest used beam's end cell is at most |r + wall| / resolution + 2
// cells away (|lx - x1| < 1, and the truncation of the end one more; one
// more margin), and no walk goes past table_size - 1 steps (add_closed_form_beam,
// add_walked_beam), nor does a range that is not finite, or a beam whose angle
// is not (a running sum of finite values can overflow to inf: its end cell
// is then no cell, and the line is walked to that cut).
int64_t scan_reach(const ScanBatch &batch, const oracle::ScanStart &start, size_t s, double wall, double resolution,
                   int64_t cut) {
  const double angles = std::fabs(start.theta) + std::fabs(batch.first_angle[s]) +
                        batch.beams_in(s) * std::fabs(batch.angle_step[s]);
  if (!std::isfinite(angles)) return cut;
  const float *r = batch.ranges_of(s);
  double longest = 0;
  for (int b = 0; b < batch.beams_in(s); ++b) {
    if (!oracle::beam_used(r[b])) continue;
    const double w = std::fabs(static_cast<double>(r[b]) + wall);
    if (!std::isfinite(w)) return cut;
    longest = std::max(longest, w);
  }
  const double cells = std::ceil(longest / resolution) + 3;
  return cells < static_cast<double>(cut) ? static_cast<int64_t>(cells) : cut;
}

// The box of the cells scans [first, last) can update, inside the grid:
// every beam's reach from its start (scan_reach). Bounded by the ranges
// before any beam is placed, so the sums are allocated once, over the cells a
// log's scans reach (fr079 at vasco's defaults: a fifth of the start cells'
// table-sized squares), and each scan's beams are added as they are placed.
Box reach_of(const ScanBatch &batch, const std::vector<oracle::ScanStart> &starts, size_t first,
             const MapperParams &params, const GridGeometry &geo) {
  const int64_t cut = std::max(params.table_size() - 1, 0);
  int64_t x0 = INT64_MAX, x1 = INT64_MIN, y0 = INT64_MAX, y1 = INT64_MIN;
  for (size_t i = 0; i < starts.size(); ++i) {
    const oracle::ScanStart &s = starts[i];
    const int64_t r = scan_reach(batch, s, first + i, params.wall_size, geo.resolution, cut);
    x0 = std::min<int64_t>(x0, s.x1 - r), x1 = std::max<int64_t>(x1, s.x1 + r);
    y0 = std::min<int64_t>(y0, s.y1 - r), y1 = std::max<int64_t>(y1, s.y1 + r);
  }
  return clipped_box(x0, x1, y0, y1, geo);
}

// A closed-form walk (egrid::LineParams) in box-relative terms: the steps
// whose cell lies in the box are [k_first, k_end) (both coordinates move
// monotonically), the minor offset as a fixed-point value, how the scratch
// index moves per step without and with a minor step, and the factor that
// turns a distance in cells into an estimate of the steps that cover it.
//
// The minor offset m(k) = floor((2bk + c) / 2a), c = a - [inc < 0]
// (egrid::line_minor_offset), is the integer part of y(k) = y0 + k * slope,
// both with 64 fraction bits: y0 = ceil(c 2^64 / 2a), slope = ceil(2b 2^64 /
// 2a). A step adds slope's fraction to y's, and the carry out is the minor
// step (slope's integer part is 1 only where b = a, and then every step is
// diagonal): an add and a mask a step, with no chain through the integer
// part and no branch to mispredict. Why it is the same m: y(k) is the exact
// (2bk + c) / 2a plus an error e in [0, (k + 1) 2^-64). The exact value is
// an integer plus a multiple of 1 / 2a, so adding less than 1 / 2a cannot
// reach the next integer: floor(y(k)) = m(k) whenever (k + 1) 2a < 2^64,
// and here k < table_size <= 1448 (EvidenceTable::kMaxEntries) and a < 2^29
// (is_closed_form_line).
struct WalkFrame {
  int64_t k_first, k_end;
  uint64_t y0, slope;        // fractions of m at step 0 and of its growth a step
  int64_t slope_int;         // 1 where b = a, else 0
  ptrdiff_t major_step, minor_step;  // scratch index moves
  ptrdiff_t axial, diagonal;          // a step's move without and with the minor step
  ptrdiff_t origin;                   // the scratch index of step 0's cell
  double steps_per_cell;      // a / sqrt(a^2 + b^2): steps to a distance, per cell of distance
};

// y(k), split into its integer part (the minor offset) and its fraction.
struct Fixed {
  int64_t m;
  uint64_t frac;
};

Fixed fixed_at(const WalkFrame &f, int64_t k) {
  const unsigned __int128 y = static_cast<unsigned __int128>(static_cast<uint64_t>(k)) * f.slope + f.y0;
  return {k * f.slope_int + static_cast<int64_t>(y >> 64), static_cast<uint64_t>(y)};
}

int64_t square_at(const WalkFrame &f, int64_t k) {
  const int64_t m = fixed_at(f, k).m;
  return k * k + m * m;
}

// The fixed point's start and step: y0 = ceil(c 2^64 / 2a) with c = a or
// a - 1, and slope = ceil(2b 2^64 / 2a) = ceil(b 2^64 / a) for b < a, from
// q = floor(2^63 / a) and r = 2^63 mod a: y0 = 2^63, or 2^63 - q (c = a - 1:
// ceil(2^63 - 2^63 / a)); slope = 2bq + ceil(2br / a), where 2br < 2a^2 <
// 2^59. Two 64-bit divisions instead of two 128-bit ones.
void fixed_point_of(uint64_t a, uint64_t b, bool c_is_a, WalkFrame *f) {
  constexpr uint64_t kHalf = uint64_t(1) << 63;
  f->slope_int = a != 0 && b == a ? 1 : 0;
  f->slope = 0;
  f->y0 = 0;
  if (a == 0) return;
  const uint64_t q = kHalf / a, r = kHalf % a;
  f->y0 = c_is_a ? kHalf : kHalf - q;
  if (b < a) f->slope = 2 * b * q + (2 * b * r + a - 1) / a;
}

bool in_box(const Box &box, int64_t x, int64_t y) {  // one unsigned compare an axis
  return static_cast<uint64_t>(x - box.x_lo) < static_cast<uint64_t>(box.width()) &&
         static_cast<uint64_t>(y - box.y_lo) < static_cast<uint64_t>(box.height());
}

// The frame of the line from (x1, y1) to (x2, y2) (p), walked for at most
// table_size steps. A line whose two ends lie in the box lies in it (the box
// is convex, and the walk's cells stay between the ends), which spares most
// beams steps_in_box's divisions.
WalkFrame frame_of(const egrid::LineParams &p, int x2, int y2, int table_size, const SumTarget &to) {
  const Box &box = to.box;
  WalkFrame f;
  const int64_t k_max = std::min(p.major_len, table_size - 1);
  if (in_box(box, p.x1, p.y1) && in_box(box, x2, y2)) {
    f.k_first = 0, f.k_end = k_max + 1;
  } else {
    int64_t k_last;
    beam_updates::steps_in_box(p, static_cast<int>(k_max), box, &f.k_first, &k_last);
    f.k_end = k_last + 1;
  }
  const uint64_t a = static_cast<uint64_t>(p.a), b = static_cast<uint64_t>(p.b);
  fixed_point_of(a, b, p.inc > 0, &f);
  const int minor_inc = p.flipped ? -p.inc : p.inc;
  const ptrdiff_t h = to.stride;  // the sums are [x][y], as the grid
  f.major_step = p.steep ? p.inc : p.inc * h;
  f.minor_step = p.steep ? minor_inc * h : minor_inc;
  f.diagonal = f.major_step + f.minor_step;
  f.axial = f.slope_int != 0 ? f.diagonal : f.major_step;
  f.origin = (int64_t(p.x1) - box.x_lo) * h + (int64_t(p.y1) - box.y_lo);
  f.steps_per_cell = a == 0 ? 0.0 : static_cast<double>(a) / std::sqrt(static_cast<double>(a * a + b * b));
  return f;
}

// The first step in [lo, hi] where `below` turns false (it is true up to a
// step and false from there on: n = k*k + m*m grows strictly with k), found
// from an estimate by stepping. Along a line sqrt(n) is within half a cell
// of k / steps_per_cell, so an estimate from the distance is at most a step
// off, and this takes two or three tests.
template <class Below>
int64_t first_not_below(int64_t lo, int64_t hi, double estimate, Below &&below) {
  int64_t k = lo;
  if (estimate >= static_cast<double>(hi)) k = hi;
  else if (estimate > static_cast<double>(lo)) k = static_cast<int64_t>(estimate);
  while (k > lo && !below(k - 1)) --k;
  while (k < hi && below(k)) ++k;
  return k;
}

// The walk at step k: the fixed point's fraction and the cell.
struct Cursor {
  int64_t k;
  uint64_t frac;
  Sum *cell;
};

Cursor cursor_at(const WalkFrame &f, Sum *acc, int64_t k) {
  const Fixed y = fixed_at(f, k);
  return {k, y.frac, acc + f.origin + k * f.major_step + y.m * f.minor_step};
}

// Adds the table's increments (free or occupied `column`, at the cell's
// (i, j) = (k, m)) to the cells of steps [c->k, k_end). A step adds the
// slope to the fraction, and the carry, as a mask (a select may compile to
// a branch, which mispredicts at every other minor step), adds the minor
// step to the cell and a row to the table entry.
void add_tabled_run(const WalkFrame &f, int64_t k_end, const float *column, int row, Cursor *c) {
  const uint64_t slope = f.slope;
  const ptrdiff_t axial = f.axial, turn = f.diagonal - f.axial;
  const ptrdiff_t table_axial = 1 + f.slope_int * row, table_turn = row - f.slope_int * row;
  uint64_t frac = c->frac;
  Sum *cell = c->cell;
  const float *inc = column + fixed_at(f, c->k).m * row + c->k;
  // This loop and add_near_run's are unrolled by four (GCC keeps the
  // remainder loop): a loop's own count and branch are a quarter of an
  // update's instructions. fr079 paper 190 -> 186 ms, fr101 defaults 356 ->
  // 335 (min of 15 renders; by two or eight: no faster).
#pragma GCC unroll 4
  for (int64_t n = k_end - c->k; n > 0; --n) {
    *cell += *inc;
    const ptrdiff_t mask = -static_cast<ptrdiff_t>(__builtin_add_overflow(frac, slope, &frac));
    cell += axial + (turn & mask);
    inc += table_axial + (table_turn & mask);
  }
  *c = {k_end, frac, cell};
}

// Adds the constant `near` to the cells of steps [c.k, k_end): most of the
// updates (all below range_sure). Where the minor step is one cell in the
// scratch (kMinor = +1 or -1: x-major lines), the cell's index and the
// fraction are one 128-bit number, and a step is one 128-bit add (or
// subtract: with the fraction complemented, its borrow is the original's
// carry), the carry going straight into the index; elsewhere (kMinor = 0)
// the carry is a mask, as above, and where the major step is one cell
// (kAxial = +1 or -1: y-major lines, but for diagonals) it is a constant
// the address arithmetic absorbs.
template <int kMinor, int kAxial>
Cursor add_near_run(const WalkFrame &f, int64_t k_end, float near, Sum *acc, Cursor c) {
  using U128 = unsigned __int128;
  if (k_end <= c.k) return c;
  const int64_t n = k_end - c.k;
  if (kMinor == 0) {
    const uint64_t slope = f.slope;
    const ptrdiff_t axial = kAxial != 0 ? kAxial : f.axial, turn = f.diagonal - axial;
    uint64_t frac = c.frac;
    Sum *cell = c.cell;
#pragma GCC unroll 4
    for (int64_t i = n; i > 0; --i) {
      *cell += near;
      const ptrdiff_t mask = -static_cast<ptrdiff_t>(__builtin_add_overflow(frac, slope, &frac));
      cell += axial + (turn & mask);
    }
    return {k_end, frac, cell};
  }
  const uint64_t idx = static_cast<uint64_t>(c.cell - acc);
  const uint64_t axial = static_cast<uint64_t>(kMinor > 0 ? f.axial : -f.axial);
  const U128 step = (U128(axial) << 64) | f.slope;
  U128 pos = (U128(idx) << 64) | (kMinor > 0 ? c.frac : ~c.frac);
#pragma GCC unroll 4
  for (int64_t i = n; i > 0; --i) {
    acc[static_cast<ptrdiff_t>(pos >> 64)] += near;
    if (kMinor > 0) pos += step;
    else pos -= step;
  }
  const uint64_t low = static_cast<uint64_t>(pos);
  return {k_end, kMinor > 0 ? low : ~low, acc + static_cast<ptrdiff_t>(pos >> 64)};
}

// Where a beam's four runs end (see add_closed_form_beam).
struct RunEnds {
  int64_t near_free, free, near_occupied, stop;
};

// A beam's four runs from `c`, for one kind of minor step (one dispatch a
// beam, the runs inlined).
template <int kMinor, int kAxial>
void walk_runs(const WalkFrame &f, const RunEnds &e, const EvidenceTable &ev, Sum *acc, Cursor c) {
  c = add_near_run<kMinor, kAxial>(f, e.near_free, ev.near_increment(true), acc, c);
  if (e.free > c.k) add_tabled_run(f, e.free, ev.column(true), ev.size(), &c);
  c = add_near_run<kMinor, kAxial>(f, e.near_occupied, ev.near_increment(false), acc, c);
  if (e.stop > c.k) add_tabled_run(f, e.stop, ev.column(false), ev.size(), &c);
}

// Adds one closed-form beam's evidence to the scratch; returns its number of
// updates. Its steps fall in four runs by n = k*k + m*m, which grows along
// the walk: free cells (n < n_free, the oracle's d < range) with the
// constant increment below n_sure and the table's beyond, then occupied ones
// likewise up to n_stop. The runs' ends are three steps: k_sure (n reaches
// n_sure), k_stop (n_stop) and k_free (d reaches the range, at most k_stop),
// each found from an estimate unless the walk ends before it.
uint64_t add_closed_form_beam(const EvidenceTable &ev, const egrid::LineParams &p, int x2, int y2, double range,
                              const SumTarget &to) {
  Sum *acc = to.base;
  const WalkFrame f = frame_of(p, x2, y2, ev.size(), to);
  const int64_t lo = f.k_first, hi = f.k_end;
  if (lo >= hi) return 0;
  // n at the last step is at most (hi - 1)^2 + b^2 (m <= b): when that is
  // below a limit, the walk ends before reaching it, with no search.
  const int64_t n_bound = (hi - 1) * (hi - 1) + int64_t(p.b) * p.b;
  const int64_t n_sure = ev.n_sure(), n_stop = ev.n_stop();
  auto below = [&f](int64_t limit) { return [&f, limit](int64_t k) { return square_at(f, k) < limit; }; };
  const double spc = f.steps_per_cell;
  const int64_t k_stop = n_bound < n_stop ? hi : first_not_below(lo, hi, ev.root_stop() * spc, below(n_stop));
  const int64_t k_sure = n_bound < n_sure ? hi : first_not_below(lo, k_stop, ev.root_sure() * spc, below(n_sure));
  const double cells = ev.cells(range);
  // The oracle's test d(n) < range without a square root where n is clearly
  // on one side: n against (range / res)^2 with a relative margin of 1e-9,
  // a million times the roundings of the test and of the bound.
  const double sq = cells * cells, n_lo = range > 0 ? sq * (1 - 1e-9) : -1, n_hi = range > 0 ? sq * (1 + 1e-9) : -1;
  const int64_t k_free = first_not_below(lo, k_stop, cells * spc, [&](int64_t k) {
    const int64_t n = square_at(f, k);
    const double dn = static_cast<double>(n);
    if (dn < n_lo) return true;
    if (dn > n_hi) return false;
    return ev.closer_than(n, range);
  });
  const RunEnds e{std::min(k_free, k_sure), k_free, std::max(k_free, k_sure), k_stop};
  const Cursor c = cursor_at(f, acc, lo);
  if (f.minor_step == 1) walk_runs<1, 0>(f, e, ev, acc, c);
  else if (f.minor_step == -1) walk_runs<-1, 0>(f, e, ev, acc, c);
  else if (f.axial == 1) walk_runs<0, 1>(f, e, ev, acc, c);
  else if (f.axial == -1) walk_runs<0, -1>(f, e, ev, acc, c);
  else walk_runs<0, 0>(f, e, ev, acc, c);
  return static_cast<uint64_t>(k_stop - lo);
}

// A line the closed form does not cover (e.g. from a range of -inf), or a
// table too large to build: the oracle's sequential walk, with its stop at a
// cell past the table, and increments computed.
uint64_t add_walked_beam(const EvidenceTable &ev, int x1, int y1, int x2, int y2, const GridGeometry &geo,
                         int64_t n_free, const SumTarget &to) {
  const Box &box = to.box;
  uint64_t updates = 0;
  const int t = ev.size();
  egrid::walk_beam_cells(x1, y1, x2, y2, t, geo.size_x, geo.size_y, [&](int cx, int cy, int i, int j) {
    if (i < 0 || j < 0 || i >= t || j >= t) return false;  // kFarDistance: stops
    const int64_t n = int64_t(i) * i + int64_t(j) * j;
    if (n >= ev.n_stop()) return false;
    // reach_of's box holds every cell a walk reaches; past it would be past the sums.
    if (cx < box.x_lo || cx >= box.x_hi || cy < box.y_lo || cy >= box.y_hi) return true;
    to.base[static_cast<ptrdiff_t>(cx - box.x_lo) * to.stride + (cy - box.y_lo)] += ev.increment(n, n < n_free);
    ++updates;
    return true;
  });
  return updates;
}

// Scans placed at a time before their beams are added (fr079: 23,000 beams,
// 370 KB of PlacedBeam, in L2).
constexpr size_t kScansPerChunk = 64;

class CpuFloatRenderer : public HostGridRenderer {
 public:
  // The call's sums cover the cells its scans reach, about the whole grid for
  // a full render: sizeof(Sum) a cell besides the grid, for the budget.
  CpuFloatRenderer() : HostGridRenderer("cpu_float", false, sizeof(Sum)) {}

  // On a grid holding an earlier map: sums in the scratch over the box, then
  // each touched cell's probability updated.
  void apply_to(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
                const GridGeometry &geo, float *cells, MapStats *stats) override {
    render(batch, first, last, params, geo, stats, [&](const Box &box) {
      assign_on_huge_pages(scratch_, box.cells(), kUntouched);
      return SumTarget{scratch_.data(), box.height(), box};
    }, [&](const EvidenceTable &ev, const Box &box) { merge(ev, box, geo, cells); });
  }

  // On a grid just reset: the sums in the grid's own cells (no scratch), the
  // box marked untouched first, then turned into probabilities in place, and
  // the stale cells outside it made unknown. Each cell of the box is
  // written twice, where a reset, the scratch's fill, its read and the merge
  // were four passes (a large site's re-render: docs/performance.md).
  Box apply_to_reset(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
                     const GridGeometry &geo, const CellRange &stale, float *cells, MapStats *stats) override {
    Box reached;  // empty where there are no scans
    render(batch, first, last, params, geo, stats, [&](const Box &box) {
      fill_box(cells, geo, box, kUntouched);
      reached = box;
      return SumTarget{cells + egrid::cell_index(box.x_lo, box.y_lo, geo.size_y), geo.size_y, box};
    }, [&](const EvidenceTable &ev, const Box &box) { convert_in_place(ev, box, geo, cells); });
    clear_outside(cells, geo, stale, reached);  // the walks write inside the box only
    return reached;
  }

 private:
  // The scans' beams placed and their evidence summed into the target that
  // `prepare(box)` returns for the box they reach, then `finish(ev, box)`.
  template <class Prepare, class Finish>
  void render(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params, const GridGeometry &geo,
              MapStats *stats, Prepare &&prepare, Finish &&finish) {
    const auto t0 = std::chrono::steady_clock::now();
    MapStats st;
    last = std::min(last, batch.num_scans());
    first = std::min(first, last);
    st.scans = last - first;
    if (first < last) {
      const std::vector<oracle::ScanStart> starts = place_scans(batch, geo, first, last);
      const EvidenceTable &ev = table_for(params);
      const Box box = reach_of(batch, starts, first, params, geo);
      const SumTarget to = prepare(box);
      // A chunk of scans at a time, in (scan, beam) order: the same sums as
      // placing every beam first, with the chunk's beams still in cache.
      for (size_t c = first; c < last; c += kScansPerChunk) {
        const size_t c_end = std::min(last, c + kScansPerChunk);
        size_t n = 0;
        for (size_t s = c; s < c_end; ++s) {
          const size_t cap = n + static_cast<size_t>(batch.beams_in(s));
          if (beams_.size() < cap) beams_.resize(cap);
          const size_t used = placer_.place(batch, geo, params, starts[s - first], s, static_cast<uint32_t>(s - first),
                                            beams_.data() + n);
          st.beams_skipped += static_cast<uint64_t>(batch.beams_in(s)) - used;
          n += used;
        }
        st.beams_used += n;
        st.cell_updates += add_beams(starts, beams_.data(), n, ev, geo, to);
      }
      finish(ev, box);
    }
    st.map_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (stats != nullptr) *stats = st;
  }

  const EvidenceTable &table_for(const MapperParams &params) {
    table_key_.ensure(params, [&] { table_ = std::make_unique<EvidenceTable>(params); });
    return *table_;
  }

  // Placed beams, their scans' starts in `starts`.
  uint64_t add_beams(const std::vector<oracle::ScanStart> &starts, const PlacedBeam *beams, size_t n,
                     const EvidenceTable &ev, const GridGeometry &geo, const SumTarget &to) {
    uint64_t updates = 0;
    for (size_t i = 0; i < n; ++i) {
      const PlacedBeam &b = beams[i];
      const oracle::ScanStart &s = starts[b.scan];
      if (ev.tabulated() && egrid::is_closed_form_line(s.x1, s.y1, b.x2, b.y2)) {
        updates += add_closed_form_beam(ev, egrid::line_params(s.x1, s.y1, b.x2, b.y2), b.x2, b.y2,
                                        static_cast<double>(b.range), to);
      } else {
        updates += add_walked_beam(ev, s.x1, s.y1, b.x2, b.y2, geo, ev.n_free(static_cast<double>(b.range)), to);
      }
    }
    return updates;
  }

  // A cell's probability from its log-odds before the call and its sum.
  static float probability(double logit_before, Sum sum) {
    const double odds = std::exp(logit_before + sum);
    return static_cast<float>(1.0 - 1.0 / (1.0 + odds));
  }

  // Each touched cell once: its log-odds (the prior's if unknown) plus the
  // sum, back to a probability.
  void merge(const EvidenceTable &ev, const Box &box, const GridGeometry &geo, float *cells) const {
    const double lp = ev.logit_prior();
    for (int x = 0; x < box.width(); ++x) {
      const Sum *acc = scratch_.data() + static_cast<size_t>(x) * box.height();
      float *col = cells + egrid::cell_index(box.x_lo + x, box.y_lo, geo.size_y);
      for (int y = 0; y < box.height(); ++y) {
        if (untouched(acc[y])) continue;
        col[y] = probability(col[y] == egrid::kUnknown ? lp : logit(col[y]), acc[y]);
      }
    }
  }

  // The box's sums, in the grid's cells, to probabilities from the prior;
  // a cell never updated to unknown.
  static void convert_in_place(const EvidenceTable &ev, const Box &box, const GridGeometry &geo, float *cells) {
    const double lp = ev.logit_prior();
    for (int x = box.x_lo; x < box.x_hi; ++x) {
      float *col = cells + egrid::cell_index(x, box.y_lo, geo.size_y);
      for (int y = 0; y < box.height(); ++y) col[y] = untouched(col[y]) ? egrid::kUnknown : probability(lp, col[y]);
    }
  }

  std::unique_ptr<EvidenceTable> table_;
  TableCache table_key_;  // of table_
  std::vector<Sum> scratch_;  // apply_to's sums over its box, [x][y]; kept for its allocation
  ScanBeamPlacer placer_;
  std::vector<PlacedBeam> beams_;  // a chunk's, as placed
};

}  // namespace

std::unique_ptr<HostGridRenderer> make_cpu_float_renderer() { return std::make_unique<CpuFloatRenderer>(); }

}  // namespace vasco
