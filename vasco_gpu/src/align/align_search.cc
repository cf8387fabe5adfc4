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
  std::vector<Node> top_nodes(int k, const RotatedCells &c) const;
  void descend(int k, const RotatedCells &c, const Node &node, int depth);
  void offer(int k, int tx, int ty, float sum);
  bool same_candidate(const Leaf &a, int k, int tx, int ty) const;

  const SearchSpace &s_;
  const Distinctness distinct_;
  const int keep_;
  const float floor_;
  // What a square's bound must beat: the floor, or once `keep_` leaves are
  // kept the lowest of them.
  std::atomic<float> bar_;
  std::mutex mutex_;
  std::vector<Leaf> kept_;  // best first
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

bool Search::same_candidate(const Leaf &a, int k, int tx, int ty) const {
  const double turn = std::abs(angle_difference(s_.theta(a.rotation), s_.theta(k)));
  return std::hypot(a.tx - tx, a.ty - ty) + turn * distinct_.radius_cells <= distinct_.cells;
}

bool precedes(const Leaf &a, const Leaf &b) {
  return std::make_tuple(-a.sum, a.rotation, a.tx, a.ty) < std::make_tuple(-b.sum, b.rotation, b.tx, b.ty);
}

// A leaf replaces the kept ones it is the same candidate as when it beats
// them all, and joins the kept otherwise; beyond keep_ the lowest goes.
void Search::offer(int k, int tx, int ty, float sum) {
  const Leaf leaf{k, tx, ty, sum};
  std::lock_guard<std::mutex> lock(mutex_);
  for (const Leaf &old : kept_)
    if (same_candidate(old, k, tx, ty) && !precedes(leaf, old)) return;
  kept_.erase(std::remove_if(kept_.begin(), kept_.end(), [&](const Leaf &old) { return same_candidate(old, k, tx, ty); }),
              kept_.end());
  kept_.insert(std::upper_bound(kept_.begin(), kept_.end(), leaf, precedes), leaf);
  if (static_cast<int>(kept_.size()) > keep_) kept_.pop_back();
  if (static_cast<int>(kept_.size()) == keep_) bar_.store(std::max(floor_, kept_.back().sum));
}

// Depth first, the children best bound first (Cartographer's order): good
// leaves come early and raise the bar that prunes the rest.
void Search::descend(int k, const RotatedCells &c, const Node &node, int depth) {
  if (depth == 0) {
    if (node.bound > bar_.load(std::memory_order_relaxed)) offer(k, node.tx, node.ty, node.bound);
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
    if (!(children[i].bound > bar_.load(std::memory_order_relaxed))) break;
    descend(k, c, children[i], depth - 1);
  }
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
      if (!(top_bound(k) > bar_.load())) continue;
      const RotatedCells c = cells_at(k);
      for (const Node &node : tops[static_cast<size_t>(k)]) {
        if (!(node.bound > bar_.load())) break;
        descend(k, c, node, depth);
      }
    }
  });
  return kept_;
}

}  // namespace

std::vector<Leaf> branch_and_bound(const SearchSpace &space, float floor_sum, int keep, const Distinctness &distinct,
                                   int threads) {
  if (space.rotations <= 0 || space.points == nullptr || space.points->size() == 0) return {};
  Search search(space, floor_sum, keep, distinct);
  return search.run(std::max(1, threads));
}

}  // namespace align_detail
}  // namespace vasco
