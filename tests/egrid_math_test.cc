// Tests of the shared per-cell math (egrid_math.h): the same functions the
// CUDA kernels run.
#include "test_seed.h"
#include "vasco_gpu/internal/egrid_math.h"

#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

namespace vasco {
namespace egrid {
namespace {

using Cells = std::vector<std::pair<int, int>>;

Cells walk(int x1, int y1, int x2, int y2) {
  BresenhamLine l;
  bresenham_init(l, x1, y1, x2, y2);
  Cells out;
  do {
    int cx, cy;
    bresenham_current(l, &cx, &cy);
    out.emplace_back(cx, cy);
  } while (bresenham_next(l) && out.size() < 100000);
  return out;
}

// Expected cells traced by hand with the rules of DESIGN §2.1.
TEST(Bresenham, ShallowPositive) {
  // dX=5, dY=2: E=4, NE=-6, D starts at -1: minor steps after cells 1, 3.
  EXPECT_EQ(walk(0, 0, 5, 2), (Cells{{0, 0}, {1, 0}, {2, 1}, {3, 1}, {4, 2}, {5, 2}}));
}

TEST(Bresenham, ShallowNegativeDirectionTakesMinorStepOnlyWhenDPositive) {
  // Reverse of the above: inc=-1, D starts at -1; D == 0 never occurs here
  // but the minor step happens when D > 0.
  EXPECT_EQ(walk(5, 2, 0, 0), (Cells{{5, 2}, {4, 2}, {3, 1}, {2, 1}, {1, 0}, {0, 0}}));
}

TEST(Bresenham, TieBreakDependsOnDirection) {
  // dX=2, dY=1: D starts at 0. Going forward D=0 takes the minor step at
  // once; going backward (inc<0, D<=0) it does not.
  EXPECT_EQ(walk(0, 0, 2, 1), (Cells{{0, 0}, {1, 1}, {2, 1}}));
  EXPECT_EQ(walk(2, 1, 0, 0), (Cells{{2, 1}, {1, 1}, {0, 0}}));
}

TEST(Bresenham, SinglePointIsNotSteep) {
  EXPECT_EQ(walk(3, 4, 3, 4), (Cells{{3, 4}}));
}

TEST(Bresenham, VerticalIsSteep) {
  EXPECT_EQ(walk(1, 1, 1, 4), (Cells{{1, 1}, {1, 2}, {1, 3}, {1, 4}}));
  EXPECT_EQ(walk(1, 1, 1, -1), (Cells{{1, 1}, {1, 0}, {1, -1}}));
}

TEST(Bresenham, FlippedShallow) {
  // (0,0) -> (5,-2): the mirror image of ShallowPositive.
  EXPECT_EQ(walk(0, 0, 5, -2), (Cells{{0, 0}, {1, 0}, {2, -1}, {3, -1}, {4, -2}, {5, -2}}));
}

TEST(Bresenham, SteepFlipped) {
  // (0,0) -> (-2,5): swap gives (0,0)->(5,-2) in the swapped frame.
  EXPECT_EQ(walk(0, 0, -2, 5), (Cells{{0, 0}, {0, 1}, {-1, 2}, {-1, 3}, {-2, 4}, {-2, 5}}));
}

TEST(Bresenham, DiagonalIsNotSteep) {
  EXPECT_EQ(walk(0, 0, 3, 3), (Cells{{0, 0}, {1, 1}, {2, 2}, {3, 3}}));
  EXPECT_EQ(walk(0, 0, -3, 3), (Cells{{0, 0}, {-1, 1}, {-2, 2}, {-3, 3}}));
}

TEST(Bresenham, EndsIncludedAndLengthIsMajorDeltaPlusOne) {
  const Cells c = walk(-7, 3, 12, -4);
  ASSERT_EQ(c.size(), 20u);
  EXPECT_EQ(c.front(), std::make_pair(-7, 3));
  EXPECT_EQ(c.back(), std::make_pair(12, -4));
}

// The per-thread closed form must give exactly the sequential walk's cells.
TEST(Bresenham, ClosedFormMatchesSequentialWalkOnAMillionRandomSegments) {
  std::mt19937 rng(testing_support::test_seed(20261123));
  std::uniform_int_distribution<int> small(-40, 40);
  std::uniform_int_distribution<int> large(-3000, 3000);
  std::uniform_int_distribution<int> coin(0, 3);
  for (int n = 0; n < 1000000; ++n) {
    auto &dist = coin(rng) == 0 ? large : small;
    const int x1 = dist(rng), y1 = dist(rng), x2 = dist(rng), y2 = dist(rng);
    const Cells a = walk(x1, y1, x2, y2);
    const LineParams p = line_params(x1, y1, x2, y2);
    ASSERT_EQ(static_cast<size_t>(p.major_len) + 1, a.size()) << x1 << "," << y1 << " -> " << x2 << "," << y2;
    for (int k = 0; k <= p.major_len; ++k) {
      int cx, cy;
      line_cell(p, k, &cx, &cy);
      ASSERT_EQ(std::make_pair(cx, cy), a[k]) << "step " << k << " of " << x1 << "," << y1 << " -> " << x2 << "," << y2;
      ASSERT_EQ(line_step_of_cell(p, cx, cy), k);
    }
    // A cell next to the line is not on it.
    int cx, cy;
    line_cell(p, p.major_len / 2, &cx, &cy);
    const int k_off = line_step_of_cell(p, cx + (p.steep ? 1 : 0), cy + (p.steep ? 0 : 1));
    ASSERT_EQ(k_off, -1);
  }
}

TEST(Bresenham, ClosedFormQualification) {
  EXPECT_TRUE(is_closed_form_line(0, 0, 46340, -46340));  // |dx * dy| = 2147395600 fits an int
  EXPECT_FALSE(is_closed_form_line(0, 0, 46341, 46341));  // 2147488281 does not
  EXPECT_FALSE(is_closed_form_line(500, 500, INT_MIN, 3));
}

TEST(IntegerSemantics, FlipFollowsCarmensWrappedProduct) {
  // dx * dy = 65536 * 32768 = 2^31, which CARMEN's int product wraps to
  // INT_MIN: the line counts as "flipped" though both deltas are positive.
  // Worked by hand from DESIGN 2.1: y is negated, DY = -32768, DX = 65536,
  // inc = +1, D = 2DY - DX < 0 and IncrE = 2DY < 0, so D never turns
  // non-negative and the walk never takes a minor step: CARMEN walks this
  // line flat along y = 0, not along y = x / 2.
  BresenhamLine l;
  bresenham_init(l, 0, 0, 65536, 32768);
  EXPECT_TRUE(l.flipped);
  for (int k = 0; k < 100; ++k) ASSERT_TRUE(bresenham_next(l));
  int cx, cy;
  bresenham_current(l, &cx, &cy);
  EXPECT_EQ(cx, 100);
  EXPECT_EQ(cy, 0);
}

TEST(IntegerSemantics, DistanceOfTheTableWrapsLikeCarmensInt) {
  // sqrt(i*i + j*j) with int i*i + j*j: 46341^2 = 2147488281 wraps to
  // -2147479015 in 32 bits, whose sqrt is NaN, as CARMEN's table would hold.
  EXPECT_TRUE(std::isnan(cell_distance(46341, 0, 1.0)));
  EXPECT_EQ(cell_distance(3, 4, 0.5), 2.5);
}

TEST(IntegerSemantics, TruncToIntIsCvttsd2si) {
  EXPECT_EQ(trunc_to_int(2.9), 2);
  EXPECT_EQ(trunc_to_int(-2.9), -2);
  EXPECT_EQ(trunc_to_int(-0.5), 0);
  EXPECT_EQ(trunc_to_int(NAN), INT_MIN);
  EXPECT_EQ(trunc_to_int(INFINITY), INT_MIN);
  EXPECT_EQ(trunc_to_int(-INFINITY), INT_MIN);
  EXPECT_EQ(trunc_to_int(3e9), INT_MIN);
  EXPECT_EQ(trunc_to_int(2147483647.0), INT_MAX);
  EXPECT_EQ(trunc_to_int(-2147483648.0), INT_MIN);
}

TEST(IntegerSemantics, DegenerateEndCellDoesNotHang) {
  // A range of -inf gives an end cell of INT_MIN; CARMEN's walk wraps. Only
  // the first steps matter (oracle.h); walking them must be well defined.
  BresenhamLine l;
  bresenham_init(l, 100, 100, INT_MIN, INT_MIN);
  for (int k = 0; k < 1000; ++k) ASSERT_TRUE(bresenham_next(l));
}

// carmen-formats.md §4.3 "Worked check": from -1 with prior 0.5, p = .55,
// .55, .45, .45, .45 gives these floats.
TEST(OddsUpdate, WorkedCheckFromTheFormatNotes) {
  float c = kUnknown;
  const double ps[] = {0.55, 0.55, 0.45, 0.45, 0.45};
  const float expected[] = {0.55000001f, 0.59900993f, 0.55000001f, 0.5f, 0.44999999f};
  for (int i = 0; i < 5; ++i) {
    c = odds_update(c, 0.5, ps[i]);
    EXPECT_EQ(c, expected[i]) << "update " << i;
  }
}

// The single float step: 1 - old is int minus float in CARMEN's C.
TEST(OddsUpdate, OneMinusOldIsAFloatSubtraction) {
  const float old = 0.1f;
  // Written out independently of odds_update, step by step from DESIGN §2.
  const double prior = 0.4, p = 0.45;
  double t = (1 - prior) / prior;
  t = t * p;
  t = t / (1 - p);
  t = t * (double)old;
  const float one_minus_old = 1.0f - old;  // float arithmetic
  t = t / (double)one_minus_old;
  const float expected = (float)(1 - 1 / (1 + t));
  EXPECT_EQ(odds_update(old, prior, p), expected);
  // And the difference matters for this value: (double)(1.0f - 0.1f) is not
  // 1.0 - (double)0.1f.
  EXPECT_NE((double)(1.0f - old), 1.0 - (double)old);
}

TEST(OddsUpdate, UnknownCellStartsFromTheFloatPrior) {
  // With prior 0.4 the first update reads (double)(float)0.4, not 0.4.
  const double prior = 0.4, p = 0.7;
  const float f_prior = (float)prior;
  double t = (1 - prior) / prior * p / (1 - p) * (double)f_prior / (double)(1.0f - f_prior);
  EXPECT_EQ(odds_update(kUnknown, prior, p), (float)(1 - 1 / (1 + t)));
}

TEST(OddsUpdate, SaturatesAtOneAndStays) {
  float c = kUnknown;
  int n = 0;
  while (c != 1.0f && n < 10000) {
    c = odds_update(c, 0.5, 0.9);
    ++n;
  }
  ASSERT_EQ(c, 1.0f);
  EXPECT_LT(n, 100);
  // odds are inf now; a free update cannot bring the cell back.
  EXPECT_EQ(odds_update(c, 0.5, 0.1), 1.0f);
}

TEST(SensorModel, FreeAndOccupiedBands) {
  const SensorModel<double> m{0.5, 0.55, 0.45, 5.0, 10.0};
  double p;
  ASSERT_TRUE(sensor_model(m, 1.0, 3.0, &p));
  EXPECT_EQ(p, 0.45);  // d < r, d < sure
  ASSERT_TRUE(sensor_model(m, 3.0, 3.0, &p));
  EXPECT_EQ(p, 0.55);  // d == r: occupied
  ASSERT_TRUE(sensor_model(m, 6.0, 8.0, &p));
  EXPECT_EQ(p, 0.45 + (6.0 - 5.0) / 10.0 * (0.5 - 0.45));  // divisor is max, not max - sure
  ASSERT_TRUE(sensor_model(m, 7.5, 7.0, &p));
  EXPECT_EQ(p, 0.55 + (7.5 - 5.0) / 10.0 * (0.5 - 0.55));
  EXPECT_FALSE(sensor_model(m, 10.0, 20.0, &p));  // d >= max: the beam stops
  EXPECT_FALSE(sensor_model(m, 1e6, 3.0, &p));
}

TEST(SensorModel, CellDistanceIsTheTableValue) {
  EXPECT_EQ(cell_distance(3, 4, 0.025), 5.0 * 0.025);
  EXPECT_EQ(cell_distance(1, 1, 0.1), std::sqrt(2.0) * 0.1);
}

// The CUDA exact mode decides "distance < range" and "distance < sure" from
// i*i + j*j against first_square_not_below; checked here against the
// distance itself, cell by cell, for ranges that fall on, just below and
// just above table distances, and for ranges no cell reaches.
TEST(SensorModel, FirstSquareNotBelowSplitsTheTableLikeTheDistance) {
  const int T = 400;
  const double res = 0.025;
  const int64_t n_max = 2 * int64_t(T) * T;
  const double limits[] = {0.0,  -INFINITY, 5.0, 0.025, cell_distance(3, 4, res), std::nextafter(5.0, 0.0),
                           std::nextafter(cell_distance(7, 9, res), 1e9), 9.99, 10.0, 60.0, INFINITY};
  for (double limit : limits) {
    const int64_t cut = first_square_not_below(limit, res, n_max);
    for (int i = 0; i < T; i += 7)
      for (int j = 0; j < T; ++j)
        ASSERT_EQ(cell_distance(i, j, res) < limit, i * i + j * j < cut) << "limit " << limit << " at " << i << "," << j;
  }
  EXPECT_EQ(first_square_not_below(NAN, res, n_max), 0);  // d < NaN never holds
  EXPECT_EQ(first_square_not_below(INFINITY, res, n_max), n_max + 1);
}

}  // namespace
}  // namespace egrid
}  // namespace vasco
