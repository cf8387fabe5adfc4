// align_search.h — the global search of the alignment: branch and bound
// over (rotation, translation in whole cells), as Cartographer's fast
// correlative scan matcher (Hess et al., "Real-time loop closure in 2D
// LIDAR SLAM", 2016): for each rotation the translations are split into
// squares of 2^d cells whose bound is the moving points' sum on pooled
// level d (align_grids.h), an exact upper bound of every translation in the
// square; a square is opened only while its bound beats the best leaf found.
#ifndef VASCO_GPU_SRC_ALIGN_ALIGN_SEARCH_H
#define VASCO_GPU_SRC_ALIGN_ALIGN_SEARCH_H

#include <limits>
#include <vector>

#include "align_grids.h"

namespace vasco {
namespace align_detail {

// Translations (in cells, inclusive) searched at one rotation.
struct TranslationBox {
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;
};

// What is searched: rotation k is theta0 + k * theta_step about the points'
// centroid (c_x, c_y), with translations box[k]; the pooled levels of the
// reference's field (levels.back() the top squares' level).
struct SearchSpace {
  const Points *points = nullptr;
  double c_x = 0, c_y = 0;
  double h = 0;  // the matching cell
  double theta0 = 0, theta_step = 0;
  int rotations = 0;
  std::vector<TranslationBox> box;
  const std::vector<PooledGrid> *levels = nullptr;
  double theta(int k) const { return theta0 + k * theta_step; }
};

// A leaf: rotation k, translation (tx, ty) cells, its score's sum.
struct Leaf {
  int rotation = -1;
  int tx = 0, ty = 0;
  float sum = -std::numeric_limits<float>::infinity();
  bool found() const { return rotation >= 0; }
};

// How leaves are told apart: the distance a leaf moves the points from
// another's, the translations' difference plus the rotations' angle times
// the points' RMS radius (both in cells); leaves at most `cells` apart are
// the same candidate.
struct Distinctness {
  double radius_cells = 0;  // the points' RMS distance from their centroid, in cells
  double cells = 0;
};

// The order of leaves: the larger sum first, ties by the smallest
// (rotation, tx, ty).
bool precedes(const Leaf &a, const Leaf &b);
// Whether two leaves are at most `cells` apart (Distinctness's distance: a
// metric, the translations' Euclidean one plus the rotations' angle times
// the radius).
bool within(const SearchSpace &space, const Distinctness &d, const Leaf &a, const Leaf &b, double cells);

// The candidates both searches return, so that the GPU's and the CPU's are
// the same whatever the order their leaves come in: the peaks (leaves that
// no neighbour at their rotation beats: translations one cell away in the
// rotation's box) whose sums beat the floor, taken best first (`precedes`),
// each unless it is the same candidate as one taken, `keep` at most. This
// selects from `peaks` (every peak above the floor, or every one above a
// sum that the keep-th taken beats: the same selection).
std::vector<Leaf> best_distinct(std::vector<Leaf> peaks, const SearchSpace &space, int keep, const Distinctness &d);

// best_distinct over every peak whose sum beats `floor_sum`; none if no leaf
// beats it. On `threads` threads over rotations, the same result for any.
std::vector<Leaf> branch_and_bound(const SearchSpace &space, float floor_sum, int keep, const Distinctness &distinct,
                                   int threads);

}  // namespace align_detail
}  // namespace vasco

#endif  // VASCO_GPU_SRC_ALIGN_ALIGN_SEARCH_H
