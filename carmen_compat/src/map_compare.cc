#include "carmen_compat/map_compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <queue>
#include <stdexcept>

#include "carmen_compat/image_io.h"

namespace carmen {
namespace {

enum class CellClass { Unknown, Free, Occupied, Even };

CellClass class_of(float v) {
  if (v == -1.0f) return CellClass::Unknown;
  if (v > 0.5f) return CellClass::Occupied;
  if (v < 0.5f) return CellClass::Free;
  return CellClass::Even;
}

std::string pct(uint64_t part, uint64_t whole) {
  char buf[64];
  if (whole == 0) return "-";
  std::snprintf(buf, sizeof buf, "%.4f%%", 100.0 * double(part) / double(whole));
  return buf;
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool known(float v) { return v != -1.0f; }

// |a - b| for ranking; NaN (a damaged value) ranks above everything.
double abs_diff(float a, float b) {
  const double d = std::fabs(double(a) - double(b));
  return std::isnan(d) ? std::numeric_limits<double>::infinity() : d;
}

// One cell into the table: compare_maps and compare_grids count alike.
void add_cell(Agreement &a, float r, float t) {
  ++a.cells;
  if (same_bits(r, t)) ++a.identical;
  const bool rk = known(r), tk = known(t);
  if (rk && tk) {
    ++a.both_known;
    const double d = std::fabs(double(r) - double(t));
    if (d > a.max_abs_diff || std::isnan(d)) a.max_abs_diff = std::isnan(d) ? INFINITY : d;
    if (!(d <= 0.1)) ++a.large_diffs;
  } else if (rk != tk) {
    ++a.status_differs;
  }
  const CellClass rc = class_of(r), tc = class_of(t);
  if (rc == tc) ++a.class_agree;
  switch (rc) {
    case CellClass::Occupied:
      ++a.occupied_ref;
      a.occupied_agree += tc == rc;
      break;
    case CellClass::Free:
      ++a.free_ref;
      a.free_agree += tc == rc;
      break;
    case CellClass::Unknown:
      ++a.unknown_ref;
      a.unknown_agree += tc == rc;
      break;
    case CellClass::Even:
      break;
  }
}

void check_grid(const GridMap &g, const char *which) {
  if (g.size_x < 0 || g.size_y < 0 || g.cells.size() != size_t(g.size_x) * size_t(g.size_y))
    throw std::invalid_argument(std::string("compare_grids: grid ") + which + " has " +
                                std::to_string(g.cells.size()) + " cells for " + std::to_string(g.size_x) +
                                " x " + std::to_string(g.size_y));
}

uint64_t count_known(const std::vector<float> &cells) {
  return uint64_t(std::count_if(cells.begin(), cells.end(), known));
}

// Larger |dp| first, then x, then y: a total order, so the top N is stable.
struct RanksBefore {
  bool operator()(const CellDifference &p, const CellDifference &q) const {
    const double dp = abs_diff(p.a, p.b), dq = abs_diff(q.a, q.b);
    if (dp != dq) return dp > dq;
    return p.x != q.x ? p.x < q.x : p.y < q.y;
  }
};

// Keeps the top_n best-ranked cells without storing every difference (a
// float backend can differ in millions of cells). The heap's top is the
// worst one kept, so it is the one to drop.
class TopDifferences {
 public:
  explicit TopDifferences(size_t n) : n_(n) {}
  void offer(const CellDifference &d) {
    if (n_ == 0) return;
    if (heap_.size() < n_) {
      heap_.push(d);
    } else if (RanksBefore()(d, heap_.top())) {
      heap_.pop();
      heap_.push(d);
    }
  }
  std::vector<CellDifference> take() {
    std::vector<CellDifference> out;
    for (; !heap_.empty(); heap_.pop()) out.push_back(heap_.top());
    std::reverse(out.begin(), out.end());
    return out;
  }

 private:
  size_t n_;
  std::priority_queue<CellDifference, std::vector<CellDifference>, RanksBefore> heap_;
};

// The overlap of [0, a) and [shift, shift + b) on one axis: start and length.
void overlap_1d(int a, int b, int64_t shift, int *start, int *length) {
  const int64_t lo = std::max<int64_t>(0, shift), hi = std::min<int64_t>(a, int64_t(b) + shift);
  *start = hi > lo ? int(lo) : 0;
  *length = hi > lo ? int(hi - lo) : 0;
}

}  // namespace

Agreement compare_maps(const std::vector<float> &ref, const std::vector<float> &test) {
  if (ref.size() != test.size())
    throw std::invalid_argument("compare_maps: the maps differ in size (" + std::to_string(ref.size()) +
                                " vs " + std::to_string(test.size()) + " cells)");
  Agreement a;
  for (size_t i = 0; i < ref.size(); ++i) add_cell(a, ref[i], test[i]);
  return a;
}

GridComparison compare_grids(const GridMap &a, const GridMap &b, int64_t shift_x,
                             int64_t shift_y, size_t top_n) {
  check_grid(a, "A");
  check_grid(b, "B");
  GridComparison c;
  c.shift_x = shift_x;
  c.shift_y = shift_y;
  overlap_1d(a.size_x, b.size_x, shift_x, &c.x0, &c.width);
  overlap_1d(a.size_y, b.size_y, shift_y, &c.y0, &c.height);
  if (c.width == 0 || c.height == 0) c.width = c.height = 0;
  TopDifferences top(top_n);
  uint64_t known_a_inside = 0, known_b_inside = 0;
  for (int x = c.x0; x < c.x0 + c.width; ++x) {
    const size_t col_a = size_t(x) * size_t(a.size_y);
    const int64_t col_b = (x - shift_x) * int64_t(b.size_y) - shift_y;  // + y: B's cell
    for (int y = c.y0; y < c.y0 + c.height; ++y) {
      const float va = a.cells[col_a + size_t(y)], vb = b.cells[size_t(col_b + y)];
      add_cell(c.agreement, va, vb);
      known_a_inside += known(va);
      known_b_inside += known(vb);
      if (same_bits(va, vb)) continue;
      if (known(va) && known(vb)) {
        top.offer({x, y, va, vb});
      } else if (c.status_changes.size() < top_n) {
        c.status_changes.push_back({x, y, va, vb});
      }
    }
  }
  c.largest = top.take();
  c.outside = a.cells.size() + b.cells.size() - 2 * c.agreement.cells;
  c.outside_known = count_known(a.cells) - known_a_inside + count_known(b.cells) - known_b_inside;
  return c;
}

bool offset_shift(const GlobalOffset &a, const GlobalOffset &b, double resolution,
                  int64_t *shift_x, int64_t *shift_y, std::string *why) {
  const double fx = (b.x - a.x) / resolution, fy = (b.y - a.y) / resolution;
  std::string reason;
  if (!(resolution > 0) || !std::isfinite(fx) || !std::isfinite(fy) || !std::isfinite(a.theta) ||
      !std::isfinite(b.theta)) {
    reason = "an offset or the resolution is not a finite number";
  } else if (a.theta != 0 || b.theta != 0) {
    // CARMEN leaves theta unused; whether it would rotate the grid is unclear,
    // so a shift is not guessed.
    reason = "an offset has theta != 0";
  } else if (std::fabs(fx) > 2e9 || std::fabs(fy) > 2e9) {
    reason = "the offsets are too far apart";
  } else if (std::fabs(fx - std::round(fx)) > 1e-6 || std::fabs(fy - std::round(fy)) > 1e-6) {
    reason = "the offsets are not a whole number of cells apart";
  }
  if (!reason.empty()) {
    if (why) *why = reason;
    return false;
  }
  *shift_x = int64_t(std::llround(fx));
  *shift_y = int64_t(std::llround(fy));
  return true;
}

namespace {

struct Rgb {
  uint8_t r, g, b;
};

// How far a changed cell's colour is from pale: 0 for |dp| <= 1e-6, 1 for
// |dp| >= 1, log scale between (float backends differ by 1e-7..1e-2, and
// those differences must still show).
double strength(double dp) {
  if (!(dp > 1e-6)) return 0;
  return std::min(1.0, 1.0 + std::log10(dp) / 6.0);
}

Rgb difference_colour(float a, float b) {
  const bool ka = known(a), kb = known(b);
  if (ka && !kb) return {255, 0, 255};  // magenta: known in A only
  if (!ka && kb) return {0, 200, 0};    // green: known in B only
  const uint8_t pale = uint8_t(std::lround(170.0 * (1.0 - strength(abs_diff(a, b)))));
  if (b > a || std::isnan(b)) return {255, pale, pale};  // red: B higher
  return {pale, pale, 255};                              // blue: B lower (or -0 vs 0)
}

}  // namespace

std::vector<uint8_t> difference_image_rgb(const GridMap &a, const GridMap &b,
                                          const GridComparison &cmp) {
  std::vector<uint8_t> rgb(size_t(cmp.width) * size_t(cmp.height) * 3);
  uint8_t *p = rgb.data();
  for (int row = 0; row < cmp.height; ++row) {
    const int y = cmp.y0 + cmp.height - 1 - row;  // row 0 is the top: y points up
    for (int x = cmp.x0; x < cmp.x0 + cmp.width; ++x, p += 3) {
      const float va = a.cells[size_t(x) * size_t(a.size_y) + size_t(y)];
      const float vb = b.cells[size_t((x - cmp.shift_x) * int64_t(b.size_y) + (y - cmp.shift_y))];
      Rgb c;
      if (same_bits(va, vb)) {
        const uint8_t g = png_pixel(va);
        c = {g, g, g};
      } else {
        c = difference_colour(va, vb);
      }
      p[0] = c.r;
      p[1] = c.g;
      p[2] = c.b;
    }
  }
  return rgb;
}

std::string Agreement::table(const std::string &title) const {
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "%s\n"
                "  cells %llu, known in both %llu, bit-identical %s\n"
                "  max |dp| (known in both) %.3g, |dp| > 0.1 in %llu cells (%s of known), known/unknown differs %llu (%s)\n"
                "  class agreement %s: occupied %s of %llu, free %s of %llu, unknown %s of %llu\n",
                title.c_str(), (unsigned long long)cells, (unsigned long long)both_known,
                pct(identical, cells).c_str(), max_abs_diff, (unsigned long long)large_diffs,
                pct(large_diffs, both_known).c_str(), (unsigned long long)status_differs,
                pct(status_differs, cells).c_str(), pct(class_agree, cells).c_str(),
                pct(occupied_agree, occupied_ref).c_str(), (unsigned long long)occupied_ref,
                pct(free_agree, free_ref).c_str(), (unsigned long long)free_ref,
                pct(unknown_agree, unknown_ref).c_str(), (unsigned long long)unknown_ref);
  return buf;
}

}  // namespace carmen
