#include "align_search.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <tuple>

#include "align_score.h"
#include "vasco_gpu/internal/parallel.h"
#include "vasco_gpu/internal/se2.h"

namespace vasco {
namespace align_detail {
namespace {

struct Node {
  int tx, ty;
  float bound;
};

// The moving points' cells at one rotation.
struct RotatedCells {
  std::vector<int32_t> x, y;
};

class Search {
 public:
  Search(const SearchSpace &space, float floor_sum, int keep, const Distinctness &distinct)
      : s_(space), distinct_(distinct), keep_(std::max(1, keep)), floor_(floor_sum), bar_(floor_sum) {}

  std::vector<Leaf> run(int threads);

 private:
  RotatedCells cells_at(int k) const;
  float bound(const RotatedCells &c, int depth, int tx, int ty) const;
  bool open(float bound) const;
  bool peak(const RotatedCells &c, const Leaf &leaf) const;
  std::vector<Node> top_nodes(int k, const RotatedCells &c) const;
  void descend(int k, const RotatedCells &c, const Node &node, int depth);
  void offer(const RotatedCells &c, const Leaf &leaf);
  std::vector<Leaf> peaks_found();

  const SearchSpace &s_;
  const Distinctness distinct_;
  const int keep_;
  const float floor_;
  // What a square's bound must reach to be opened: the floor, or, once
  // `keep_` peaks are kept apart, the lowest of them (see offer).
  std::atomic<float> bar_;
  std::mutex mutex_;
  std::vector<Leaf> leaves_;  // every leaf offered: those that reach the bar when found
  std::vector<Leaf> apart_;   // peaks more than twice `distinct_.cells` apart, best first
};

RotatedCells Search::cells_at(int k) const {
  const Points &p = *s_.points;
  const int n = static_cast<int>(p.size());
  RotatedCells c;
  c.x.resize(p.size());
  c.y.resize(p.size());
  rotated_cells(p.x.data(), p.y.data(), n, s_.c_x, s_.c_y, s_.theta(k), s_.h, c.x.data(), c.y.data());
  return c;
}

float Search::bound(const RotatedCells &c, int depth, int tx, int ty) const {
  const PooledGrid &g = (*s_.levels)[static_cast<size_t>(depth)];
  return sum_at_cells(g.value.data(), g.offset, g.size_x, g.size_y, c.x.data(), c.y.data(),
                      static_cast<int>(c.x.size()), tx, ty);
}

// A square is opened (a leaf offered) where its bound beats the floor and
// is not below the bar: a peak that ends among the kept is never missed,
// ties at the bar included.
bool Search::open(float bound) const { return bound > floor_ && !(bound < bar_.load(std::memory_order_relaxed)); }

// No neighbour at the leaf's rotation (a translation one cell away, inside
// the rotation's box) has a larger sum: the GPU's peak (align_search.cu).
bool Search::peak(const RotatedCells &c, const Leaf &leaf) const {
  const TranslationBox &b = s_.box[static_cast<size_t>(leaf.rotation)];
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy) {
      const int tx = leaf.tx + dx, ty = leaf.ty + dy;
      if ((dx == 0 && dy == 0) || tx < b.x0 || tx > b.x1 || ty < b.y0 || ty > b.y1) continue;
      if (bound(c, 0, tx, ty) > leaf.sum) return false;
    }
  return true;
}

std::vector<Node> Search::top_nodes(int k, const RotatedCells &c) const {
  const int depth = static_cast<int>(s_.levels->size()) - 1;
  const int side = 1 << depth;
  const TranslationBox &b = s_.box[static_cast<size_t>(k)];
  std::vector<Node> nodes;
  for (int tx = b.x0; tx <= b.x1; tx += side)
    for (int ty = b.y0; ty <= b.y1; ty += side)
      nodes.push_back({tx, ty, bound(c, depth, tx, ty)});
  std::sort(nodes.begin(), nodes.end(), [](const Node &a, const Node &b) { return a.bound > b.bound; });
  return nodes;
}

// Every offered leaf is kept for the end (peaks_found); the bar is the
// keep-th sum of a set of peaks pairwise more than 2 * cells apart. Why
// that bar never prunes a peak that best_distinct would take: each peak q
// of the set is taken, or passed over for a taken one within `cells` of it
// and preceding it; two peaks of the set, more than 2 * cells apart, cannot
// share that one (the distance is a metric), so at least as many taken
// candidates reach any sum as peaks of the set do, and the keep-th taken
// reaches the bar. A set kept by the greedy "the same candidate" of
// `cells` instead (the search before) is not such a bound, and the order
// the threads found leaves in changed which distinct ones were kept.
void Search::offer(const RotatedCells &c, const Leaf &leaf) {
  std::lock_guard<std::mutex> lock(mutex_);
  leaves_.push_back(leaf);
  const double apart = 2 * distinct_.cells;
  for (const Leaf &old : apart_)
    if (within(s_, distinct_, old, leaf, apart) && !precedes(leaf, old)) return;
  if (static_cast<int>(apart_.size()) == keep_ && !precedes(leaf, apart_.back())) return;
  if (!peak(c, leaf)) return;  // checked last: 8 sums, under the lock, for the few that get this far
  apart_.erase(std::remove_if(apart_.begin(), apart_.end(),
                              [&](const Leaf &old) { return within(s_, distinct_, old, leaf, apart); }),
               apart_.end());
  apart_.insert(std::upper_bound(apart_.begin(), apart_.end(), leaf, precedes), leaf);
  if (static_cast<int>(apart_.size()) > keep_) apart_.pop_back();
  if (static_cast<int>(apart_.size()) == keep_)  // the bar never falls: each was a bound when set
    bar_.store(std::max({bar_.load(), floor_, apart_.back().sum}));
}

// Depth first, the children best bound first (Cartographer's order): good
// leaves come early and raise the bar that prunes the rest.
void Search::descend(int k, const RotatedCells &c, const Node &node, int depth) {
  if (depth == 0) {
    if (open(node.bound)) offer(c, Leaf{k, node.tx, node.ty, node.bound});
    return;
  }
  const TranslationBox &b = s_.box[static_cast<size_t>(k)];
  const int half = 1 << (depth - 1);
  Node children[4];
  int n = 0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      const int tx = node.tx + i * half, ty = node.ty + j * half;
      if (tx > b.x1 || ty > b.y1) continue;
      children[n++] = {tx, ty, bound(c, depth - 1, tx, ty)};
    }
  for (int i = 1; i < n; ++i)  // four at most: an insertion sort, best bound first
    for (int j = i; j > 0 && children[j].bound > children[j - 1].bound; --j) std::swap(children[j], children[j - 1]);
  for (int i = 0; i < n; ++i) {
    if (!open(children[i].bound)) break;
    descend(k, c, children[i], depth - 1);
  }
}

// The offered leaves that reach the final bar and are peaks: every peak
// that reaches it (none was pruned: its squares' bounds reached the bar of
// their time, which never exceeds the final one).
std::vector<Leaf> Search::peaks_found() {
  const float bar = bar_.load();
  std::vector<Leaf> found;
  for (const Leaf &l : leaves_)
    if (!(l.sum < bar)) found.push_back(l);
  std::sort(found.begin(), found.end(), [](const Leaf &a, const Leaf &b) { return a.rotation < b.rotation; });
  std::vector<Leaf> peaks;
  RotatedCells c;
  for (size_t i = 0; i < found.size(); ++i) {
    if (i == 0 || found[i].rotation != found[i - 1].rotation) c = cells_at(found[i].rotation);
    if (peak(c, found[i])) peaks.push_back(found[i]);
  }
  return peaks;
}

std::vector<Leaf> Search::run(int threads) {
  const int rotations = s_.rotations;
  // The top squares of every rotation first, so that the rotations are
  // searched best bound first.
  std::vector<std::vector<Node>> tops(static_cast<size_t>(rotations));
  std::atomic<int> next{0};
  run_on_threads(threads, [&](int) {
    for (int k; (k = next.fetch_add(1)) < rotations;) tops[static_cast<size_t>(k)] = top_nodes(k, cells_at(k));
  });
  std::vector<int> order(static_cast<size_t>(rotations));
  for (int k = 0; k < rotations; ++k) order[static_cast<size_t>(k)] = k;
  auto top_bound = [&](int k) { return tops[static_cast<size_t>(k)].empty() ? -1e30f : tops[static_cast<size_t>(k)][0].bound; };
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return top_bound(a) > top_bound(b); });
  const int depth = static_cast<int>(s_.levels->size()) - 1;
  next = 0;
  run_on_threads(threads, [&](int) {
    for (int i; (i = next.fetch_add(1)) < rotations;) {
      const int k = order[static_cast<size_t>(i)];
      if (!open(top_bound(k))) continue;
      const RotatedCells c = cells_at(k);
      for (const Node &node : tops[static_cast<size_t>(k)]) {
        if (!open(node.bound)) break;
        descend(k, c, node, depth);
      }
    }
  });
  return best_distinct(peaks_found(), s_, keep_, distinct_);
}

}  // namespace

bool precedes(const Leaf &a, const Leaf &b) {
  return std::make_tuple(-a.sum, a.rotation, a.tx, a.ty) < std::make_tuple(-b.sum, b.rotation, b.tx, b.ty);
}

bool within(const SearchSpace &space, const Distinctness &d, const Leaf &a, const Leaf &b, double cells) {
  const double turn = std::abs(angle_difference(space.theta(a.rotation), space.theta(b.rotation)));
  return std::hypot(a.tx - b.tx, a.ty - b.ty) + turn * d.radius_cells <= cells;
}

std::vector<Leaf> best_distinct(std::vector<Leaf> peaks, const SearchSpace &space, int keep, const Distinctness &d) {
  std::sort(peaks.begin(), peaks.end(), precedes);
  std::vector<Leaf> kept;
  for (const Leaf &leaf : peaks) {
    if (static_cast<int>(kept.size()) >= keep) break;
    if (std::none_of(kept.begin(), kept.end(), [&](const Leaf &k) { return within(space, d, k, leaf, d.cells); }))
      kept.push_back(leaf);
  }
  return kept;
}

std::vector<Leaf> branch_and_bound(const SearchSpace &space, float floor_sum, int keep, const Distinctness &distinct,
                                   int threads) {
  if (space.rotations <= 0 || space.points == nullptr || space.points->size() == 0) return {};
  Search search(space, floor_sum, keep, distinct);
  return search.run(std::max(1, threads));
}

}  // namespace align_detail
}  // namespace vasco
