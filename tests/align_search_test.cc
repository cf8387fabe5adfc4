// The alignment's global search (vasco_gpu/src/align/align_search.h) against
// every leaf scored: branch and bound must return the candidates an
// exhaustive search gives (the peaks above the floor, taken best first,
// each unless it is within `cells` of one taken), on any number of threads.
// The GPU search selects the same way from the peaks it lists (align_gpu.cc),
// so this is what makes the two searches' answers one answer
// (align_cuda_test compares them on the device).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "align_grids.h"
#include "align_score.h"
#include "align_search.h"
#include "test_seed.h"
#include "vasco_gpu/internal/se2.h"

namespace vasco {
namespace align_detail {
namespace {

// A random field, smooth (bumps three cells wide, so that a leaf's
// neighbours score nearly as it does and only the peaks rule keeps them
// out) with known-free cells (negative) in places, its pooled levels, and
// random points.
struct RandomSpace {
  Field field;
  std::vector<PooledGrid> levels;
  Points points;
  SearchSpace space;
  Distinctness distinct;

  RandomSpace(std::mt19937 &rng, int rotations) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    field.size_x = 48, field.size_y = 40;
    field.value.assign(static_cast<size_t>(field.size_x) * field.size_y, 0.0f);
    field.known.assign(field.value.size(), 1);
    for (int bump = 0; bump < 25; ++bump) {
      const float bx = u(rng) * field.size_x, by = u(rng) * field.size_y, a = u(rng);
      for (int x = 0; x < field.size_x; ++x)
        for (int y = 0; y < field.size_y; ++y)
          field.value[static_cast<size_t>(x) * field.size_y + y] +=
              a * std::exp(-((x - bx) * (x - bx) + (y - by) * (y - by)) / 18.0f);
    }
    for (float &v : field.value)
      if (u(rng) < 0.05f) v = -kFreePenalty;
    levels = pool_levels(field, 5);
    std::uniform_real_distribution<double> at(0.0, 20.0);
    for (int i = 0; i < 60; ++i) {
      points.x.push_back(at(rng));
      points.y.push_back(at(rng) * 0.7);
    }
    space.points = &points;
    space.c_x = 10, space.c_y = 7;
    space.h = 1.0;
    space.theta0 = -0.3, space.theta_step = 0.6 / rotations;
    space.rotations = rotations;
    space.box.assign(static_cast<size_t>(rotations), TranslationBox{-6, 40, -5, 33});
    space.levels = &levels;
    distinct.radius_cells = 8.0;
    distinct.cells = 3.0;
  }
};

// Every leaf scored, the peaks kept (no neighbour one cell away in the box
// at the same rotation has a larger sum), and the selection made here,
// independently of the library's.
std::vector<Leaf> exhaustive(const RandomSpace &r, float floor_sum, int keep) {
  const SearchSpace &s = r.space;
  const PooledGrid &g = r.levels.front();
  const int n = static_cast<int>(r.points.size());
  std::vector<Leaf> peaks;
  for (int k = 0; k < s.rotations; ++k) {
    std::vector<int32_t> cx(static_cast<size_t>(n)), cy(static_cast<size_t>(n));
    rotated_cells(r.points.x.data(), r.points.y.data(), n, s.c_x, s.c_y, s.theta(k), s.h, cx.data(), cy.data());
    const TranslationBox &b = s.box[static_cast<size_t>(k)];
    const auto sum = [&](int tx, int ty) {
      return sum_at_cells(g.value.data(), g.offset, g.size_x, g.size_y, cx.data(), cy.data(), n, tx, ty);
    };
    for (int tx = b.x0; tx <= b.x1; ++tx)
      for (int ty = b.y0; ty <= b.y1; ++ty) {
        const float v = sum(tx, ty);
        if (!(v > floor_sum)) continue;
        bool peak = true;
        for (int dx = -1; dx <= 1 && peak; ++dx)
          for (int dy = -1; dy <= 1 && peak; ++dy) {
            const int x = tx + dx, y = ty + dy;
            if (x >= b.x0 && x <= b.x1 && y >= b.y0 && y <= b.y1 && sum(x, y) > v) peak = false;
          }
        if (peak) peaks.push_back(Leaf{k, tx, ty, v});
      }
  }
  std::sort(peaks.begin(), peaks.end(), [](const Leaf &a, const Leaf &b) {
    return std::make_tuple(-a.sum, a.rotation, a.tx, a.ty) < std::make_tuple(-b.sum, b.rotation, b.tx, b.ty);
  });
  std::vector<Leaf> taken;
  for (const Leaf &p : peaks) {
    if (static_cast<int>(taken.size()) == keep) break;
    bool near = false;
    for (const Leaf &t : taken) {
      const double turn = std::abs(angle_difference(s.theta(p.rotation), s.theta(t.rotation)));
      near = near || std::hypot(p.tx - t.tx, p.ty - t.ty) + turn * r.distinct.radius_cells <= r.distinct.cells;
    }
    if (!near) taken.push_back(p);
  }
  return taken;
}

std::string describe(const std::vector<Leaf> &leaves) {
  std::string out;
  for (const Leaf &l : leaves)
    out += "(" + std::to_string(l.rotation) + ", " + std::to_string(l.tx) + ", " + std::to_string(l.ty) + ": " +
           std::to_string(l.sum) + ") ";
  return out;
}

TEST(AlignSearch, BranchAndBoundGivesTheExhaustiveSearchsCandidatesOnAnyThreads) {
  const unsigned seed = testing_support::test_seed();
  SCOPED_TRACE("random seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  int compared = 0;
  for (int trial = 0; trial < 6; ++trial) {
    RandomSpace r(rng, 5 + trial * 3);
    // Half a cell: a peak's neighbours are other candidates, so only the peaks rule keeps them out.
    r.distinct.cells = trial % 2 == 0 ? 3.0 : 0.5;
    for (const int keep : {1, 4, 16}) {
      const std::vector<Leaf> want = exhaustive(r, 0.0f, keep);
      for (const int threads : {1, 2, 3}) {
        const std::vector<Leaf> got = branch_and_bound(r.space, 0.0f, keep, r.distinct, threads);
        SCOPED_TRACE("trial " + std::to_string(trial) + ", keep " + std::to_string(keep) + ", threads " +
                     std::to_string(threads));
        ASSERT_EQ(got.size(), want.size()) << "got " << describe(got) << "\nwant " << describe(want);
        for (size_t i = 0; i < want.size(); ++i) {
          EXPECT_EQ(std::make_tuple(got[i].rotation, got[i].tx, got[i].ty, got[i].sum),
                    std::make_tuple(want[i].rotation, want[i].tx, want[i].ty, want[i].sum))
              << "candidate " << i << "\ngot " << describe(got) << "\nwant " << describe(want);
        }
        ++compared;
      }
    }
    ASSERT_GE(exhaustive(r, 0.0f, 16).size(), 4u) << "the field must offer several distinct peaks";
  }
  EXPECT_EQ(compared, 6 * 3 * 3);
}

// A floor above every sum: no candidate, from either.
TEST(AlignSearch, AFloorAboveEverySumGivesNoCandidate) {
  std::mt19937 rng(testing_support::test_seed());
  const RandomSpace r(rng, 4);
  EXPECT_TRUE(exhaustive(r, 1e6f, 4).empty());
  EXPECT_TRUE(branch_and_bound(r.space, 1e6f, 4, r.distinct, 2).empty());
}

}  // namespace
}  // namespace align_detail
}  // namespace vasco
