// The alignment of two maps (align.h): the grids at a coarse cell and at the
// matching cell, a global branch and bound at the coarse cell for the best
// distinct candidates, a fine one near each, their refinement, and the
// verdict on the best and the best distinct second.
#include "vasco_gpu/align.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <utility>

#include "align_gpu.h"
#include "align_grids.h"
#include "align_refine.h"
#include "align_search.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/internal/parallel.h"
#include "vasco_gpu/map_output.h"

namespace vasco {

using namespace align_detail;

namespace {

constexpr double kPi = 3.14159265358979323846;
// The largest map side and cell count at the matching cell: sides leave room
// for int cell arithmetic with translations, and the pooled levels (8 float
// grids) stay within a few GiB.
constexpr double kMaxSide = 1 << 20;
constexpr double kMaxCells = double(1 << 26);
// The top squares' side is 2^kMaxDepth cells (Cartographer's default 7):
// fewer top squares per rotation, each bounded more loosely.
constexpr int kMaxDepth = 7;
// The global search runs on cells this many times the matching cell: a
// sixteenth of the translations, a quarter of the rotations and of the
// points, and a smoother field whose bounds prune better. Its best distinct
// candidates are then searched again at the matching cell near each.
constexpr double kCoarse = 4;
constexpr int kCoarseCandidates = 6;
// Coarse leaves within this many coarse cells of movement are one candidate:
// the coarse field's peak spreads over its 2-cell reach.
constexpr double kCoarseDistinct = 3;
// A second candidate is distinct when it moves the moving map's points by
// more than this many matching cells (translation plus rotation times the
// points' RMS radius) from the best: beyond the best peak's flank.
constexpr double kDistinctCells = 6;

void check_map(const AlignMap &m, const char *which) {
  const bool sizes_ok = m.size_x >= 0 && m.size_y >= 0 &&
                        m.cells.size() == static_cast<size_t>(m.size_x) * static_cast<size_t>(m.size_y);
  if (!sizes_ok || !std::isfinite(m.resolution) || !std::isfinite(m.origin_x) || !std::isfinite(m.origin_y)) {
    std::ostringstream msg;
    msg << "align_maps: the " << which << " map has " << m.cells.size() << " cells for " << m.size_x << " x "
        << m.size_y << ", resolution " << m.resolution << ", origin (" << m.origin_x << ", " << m.origin_y << ")";
    throw Error(ErrorCode::BadInput, msg.str());
  }
}

void check_options(const AlignOptions &o) {
  if (!(std::isfinite(o.match_resolution) && o.match_resolution > 0))
    throw Error(ErrorCode::Usage, "align_maps: match_resolution must be finite and positive");
  if (o.threads < 0) throw Error(ErrorCode::Usage, "align_maps: threads must be 0 (every core) or more");
  if (o.cuda_device < 0) throw Error(ErrorCode::Usage, "align_maps: cuda_device must be 0 or more");
  if (o.hint) {
    const AlignHint &h = *o.hint;
    const bool ok = std::isfinite(h.x) && std::isfinite(h.y) && std::isfinite(h.theta) && std::isfinite(h.radius_m) &&
                    h.radius_m >= 0 && std::isfinite(h.radius_rad) && h.radius_rad >= 0;
    if (!ok) throw Error(ErrorCode::Usage, "align_maps: a hint's position, heading and radii must be finite, radii >= 0");
  }
}

// Whether a map at the matching cell is beyond the limits (sides, cells).
bool too_large(const AlignMap &m, double h) {
  if (m.size_x <= 0 || m.size_y <= 0 || !(m.resolution > 0)) return false;
  const double sx = std::ceil(m.size_x * m.resolution / h), sy = std::ceil(m.size_y * m.resolution / h);
  return sx > kMaxSide || sy > kMaxSide || sx * sy > kMaxCells;
}

// theta in (-pi, pi].
double wrapped(double theta) {
  double t = std::remainder(theta, 2 * kPi);
  if (t <= -kPi) t += 2 * kPi;
  return t;
}

// One matching cell's grids: the reference's field, the moving map's walls.
struct Level {
  double h = 0;
  MatchGrid reference;
  Field field;
  Points points;
  int reference_walls = 0;
};

Level level_at(const AlignMap &reference, const AlignMap &moving, double h) {
  Level l;
  l.h = h;
  l.reference = resample(reference, h);
  l.field = likelihood_field(l.reference);
  for (float v : l.reference.cells) l.reference_walls += v > kWallAbove;
  l.points = wall_points(resample(moving, h));
  return l;
}

// Both levels, and the fine points' centroid that every candidate turns
// about (so that a translation means the same place at every rotation and
// level).
struct Prepared {
  Level fine, coarse;
  double c_x = 0, c_y = 0;
  double r_max = 0, r_rms = 0;  // the points' distances from their centroid, metres
};

Prepared prepare(const AlignMap &reference, const AlignMap &moving, double h) {
  Prepared p;
  p.fine = level_at(reference, moving, h);
  const Points &pts = p.fine.points;
  const size_t n = pts.size();
  if (n == 0 || p.fine.reference_walls == 0) return p;
  p.coarse = level_at(reference, moving, h * kCoarse);
  for (size_t i = 0; i < n; ++i) {
    p.c_x += pts.x[i] / n;
    p.c_y += pts.y[i] / n;
  }
  double sq = 0;
  for (size_t i = 0; i < n; ++i) {
    const double r2 = std::pow(pts.x[i] - p.c_x, 2) + std::pow(pts.y[i] - p.c_y, 2);
    p.r_max = std::max(p.r_max, std::sqrt(r2));
    sq += r2;
  }
  p.r_rms = std::sqrt(sq / n);
  return p;
}

SearchSpace space_of(const Level &l, const Prepared &p) {
  SearchSpace s;
  s.points = &l.points;
  s.c_x = p.c_x;
  s.c_y = p.c_y;
  s.h = l.h;
  return s;
}

// Rotations: a step that moves the farthest point by at most one cell, so
// that the best leaf's rotation is within half a cell of the truth's at every
// point; every rotation, or those within the hint's radius.
void set_rotations(SearchSpace &s, const Prepared &p, const AlignOptions &o) {
  const double step = s.h / std::max(p.r_max, s.h);
  if (!o.hint) {
    s.rotations = static_cast<int>(std::ceil(2 * kPi / step));
    s.theta_step = 2 * kPi / s.rotations;
    s.theta0 = 0;
    return;
  }
  const double span = std::min(2 * o.hint->radius_rad, 2 * kPi);
  const int steps = static_cast<int>(std::ceil(span / step));
  s.rotations = steps + 1;
  s.theta_step = steps > 0 ? span / steps : step;
  s.theta0 = o.hint->theta - span / 2;
}

// Translations in cells: the centroid anywhere the points can still touch
// the reference (every point lies within r_max of it), within the hint's
// box (rounded outwards) when there is one. T's translation is o + t h - R c
// (align.h's T in the search's terms: rotate about c, then put c at o + t h).
void set_translations(SearchSpace &s, const MatchGrid &ref, const Prepared &p, const AlignOptions &o) {
  const int reach = static_cast<int>(std::ceil(p.r_max / s.h)) + 1;
  const TranslationBox all{-reach, ref.size_x + reach, -reach, ref.size_y + reach};
  s.box.assign(static_cast<size_t>(s.rotations), all);
  if (!o.hint) return;
  for (int k = 0; k < s.rotations; ++k) {
    const double c = std::cos(s.theta(k)), sn = std::sin(s.theta(k));
    const double rx = c * p.c_x - sn * p.c_y - ref.origin_x, ry = sn * p.c_x + c * p.c_y - ref.origin_y;
    TranslationBox &b = s.box[static_cast<size_t>(k)];
    b.x0 = std::max(b.x0, static_cast<int>(std::floor((o.hint->x - o.hint->radius_m + rx) / s.h)));
    b.x1 = std::min(b.x1, static_cast<int>(std::ceil((o.hint->x + o.hint->radius_m + rx) / s.h)));
    b.y0 = std::max(b.y0, static_cast<int>(std::floor((o.hint->y - o.hint->radius_m + ry) / s.h)));
    b.y1 = std::min(b.y1, static_cast<int>(std::ceil((o.hint->y + o.hint->radius_m + ry) / s.h)));
  }
}

// The fine search near a coarse leaf: its rotation and translation plus or
// minus one and a half coarse steps (the coarse leaf lies within half a step
// of its own peak, which lies within a step of the fine one).
SearchSpace fine_space_near(const Leaf &coarse_leaf, const SearchSpace &coarse, const Prepared &p) {
  SearchSpace s = space_of(p.fine, p);
  const double step = s.h / std::max(p.r_max, s.h);
  const double span = 3 * coarse.theta_step;
  const int steps = static_cast<int>(std::ceil(span / step));
  s.rotations = steps + 1;
  s.theta_step = span / steps;
  s.theta0 = coarse.theta(coarse_leaf.rotation) - span / 2;
  const double reach = 1.5 * coarse.h;
  TranslationBox b;
  b.x0 = static_cast<int>(std::floor((coarse_leaf.tx * coarse.h - reach) / s.h));
  b.x1 = static_cast<int>(std::ceil((coarse_leaf.tx * coarse.h + reach) / s.h));
  b.y0 = static_cast<int>(std::floor((coarse_leaf.ty * coarse.h - reach) / s.h));
  b.y1 = static_cast<int>(std::ceil((coarse_leaf.ty * coarse.h + reach) / s.h));
  s.box.assign(static_cast<size_t>(s.rotations), b);
  return s;
}

// Levels so that the top squares are no larger than the widest box needs.
int level_count(const SearchSpace &s) {
  int widest = 1;
  for (const TranslationBox &b : s.box) widest = std::max({widest, b.x1 - b.x0 + 1, b.y1 - b.y0 + 1});
  int depth = 0;
  while (depth < kMaxDepth && (1 << depth) < widest) ++depth;
  return depth + 1;
}

// A candidate found, refined: align.h's form and the search's.
struct Found {
  AlignCandidate candidate;
  Placement placement;
};

Found refined(const Leaf &leaf, const SearchSpace &s, const Prepared &p, const RefineInput &in) {
  Found f;
  double sum = 0;
  f.placement = refine(in, {s.theta(leaf.rotation), leaf.tx * s.h, leaf.ty * s.h}, s.theta_step, &sum);
  const double c = std::cos(f.placement.theta), sn = std::sin(f.placement.theta);
  f.candidate.theta = wrapped(f.placement.theta);
  f.candidate.x = p.fine.reference.origin_x + f.placement.tx - (c * p.c_x - sn * p.c_y);
  f.candidate.y = p.fine.reference.origin_y + f.placement.ty - (sn * p.c_x + c * p.c_y);
  f.candidate.score = sum / static_cast<double>(p.fine.points.size());
  return f;
}

// With VASCO_ALIGN_PROFILE set, each stage's time to stderr: where an
// alignment's time goes (for tuning; the benchmark times whole calls).
class StageClock {
 public:
  StageClock() : on_(std::getenv("VASCO_ALIGN_PROFILE") != nullptr), last_(std::chrono::steady_clock::now()) {}
  void mark(const char *stage) {
    if (!on_) return;
    const auto now = std::chrono::steady_clock::now();
    std::fprintf(stderr, "  [align] %-14s %9.3f ms\n", stage,
                 std::chrono::duration<double, std::milli>(now - last_).count());
    last_ = now;
  }

 private:
  bool on_;
  std::chrono::steady_clock::time_point last_;
};

// Whether the global search runs on the GPU (AlignOptions::backend).
bool gpu_chosen(const AlignOptions &o) {
  if (o.backend == AlignOptions::Backend::Cpu) return false;
  std::string why;
  const bool usable = gpu_search_compiled() && gpu_usable(o.cuda_device, &why);
  if (o.backend == AlignOptions::Backend::Gpu && !usable)
    throw Error(ErrorCode::NoGpu, "align_maps: backend gpu, but " +
                                      (gpu_search_compiled() ? why : std::string("this build has no CUDA")));
  return usable;
}

// The coarse search's best distinct leaves, on the GPU when *on_gpu (which
// a GPU without the memory, or gone, clears where the backend is Auto).
std::vector<Leaf> coarse_leaves(const SearchSpace &coarse, const Distinctness &distinct, const AlignOptions &o,
                                int threads, bool *on_gpu) {
  if (*on_gpu) {
    try {
      return gpu_search(coarse, 0.0f, kCoarseCandidates, distinct, threads, o.cuda_device);
    } catch (const Error &e) {
      const bool gpu_gone = e.code() == ErrorCode::NoGpu || e.code() == ErrorCode::OutOfMemory;
      if (o.backend != AlignOptions::Backend::Auto || !gpu_gone) throw;
      *on_gpu = false;
    }
  }
  return branch_and_bound(coarse, 0.0f, kCoarseCandidates, distinct, threads);
}

// The global coarse search, then the fine one near each coarse candidate:
// the refined candidates, best first.
std::vector<Found> search(const Prepared &p, const AlignOptions &o, int threads, int *rotations, bool *on_gpu) {
  StageClock clock;
  SearchSpace coarse = space_of(p.coarse, p);
  set_rotations(coarse, p, o);
  set_translations(coarse, p.coarse.reference, p, o);
  *rotations = coarse.rotations;
  const std::vector<PooledGrid> coarse_levels = pool_levels(p.coarse.field, level_count(coarse));
  coarse.levels = &coarse_levels;
  const Distinctness coarse_distinct{p.r_rms / coarse.h, std::max(kCoarseDistinct, kDistinctCells / kCoarse)};
  clock.mark("coarse levels");
  const std::vector<Leaf> leaves = coarse_leaves(coarse, coarse_distinct, o, threads, on_gpu);
  clock.mark(*on_gpu ? "coarse (gpu)" : "coarse (cpu)");
  const RefineInput in{&p.fine.field, p.fine.h, &p.fine.points, p.c_x, p.c_y};
  std::vector<PooledGrid> fine_levels;
  std::vector<std::pair<Leaf, SearchSpace>> fine_best;
  for (const Leaf &leaf : leaves) {
    SearchSpace fine = fine_space_near(leaf, coarse, p);
    if (fine_levels.size() < static_cast<size_t>(level_count(fine)))
      fine_levels = pool_levels(p.fine.field, level_count(fine));
    fine.levels = &fine_levels;
    const std::vector<Leaf> best = branch_and_bound(fine, -1e30f, 1, {}, threads);
    if (!best.empty()) fine_best.emplace_back(best[0], fine);
  }
  clock.mark("fine");
  // Each refinement climbs alone, one candidate a thread (the search's
  // threads split rotations instead).
  std::vector<Found> found(fine_best.size());
  std::atomic<size_t> next{0};
  run_on_threads(std::max(1, std::min(threads, static_cast<int>(found.size()))), [&](int) {
    for (size_t i; (i = next.fetch_add(1)) < found.size();)
      found[i] = refined(fine_best[i].first, fine_best[i].second, p, in);
  });
  clock.mark("refine");
  std::stable_sort(found.begin(), found.end(),
                   [](const Found &a, const Found &b) { return a.candidate.score > b.candidate.score; });
  return found;
}

// Whether two placements move the points by more than kDistinctCells.
bool distinct(const Found &a, const Found &b, const Prepared &p) {
  const double turn = std::abs(std::remainder(a.placement.theta - b.placement.theta, 2 * kPi));
  const double moved = std::hypot(a.placement.tx - b.placement.tx, a.placement.ty - b.placement.ty) + turn * p.r_rms;
  return moved > kDistinctCells * p.fine.h;
}

AlignResult refused(AlignResult r, const std::string &reason) {
  r.verdict = AlignVerdict::NoOverlap;
  r.reason = reason;
  return r;
}

// The verdict on a searched result (min_score, min_matched, ambiguity).
AlignResult judged(AlignResult r, const AlignOptions &o) {
  std::ostringstream why;
  why.precision(3);
  if (r.best.score < o.min_score) {
    why << "the best candidate scores " << r.best.score << ", below " << o.min_score;
    return refused(r, why.str());
  }
  if (r.matched < o.min_matched) {
    why << "the best candidate lays " << r.matched << " wall cells on the reference's walls, fewer than "
        << o.min_matched;
    return refused(r, why.str());
  }
  if (r.has_second && r.second.score >= o.ambiguity * r.best.score) {
    r.verdict = AlignVerdict::Ambiguous;
    why << "a distinct second candidate scores " << r.second.score << ", at least " << o.ambiguity
        << " of the best's " << r.best.score;
    r.reason = why.str();
    return r;
  }
  r.verdict = AlignVerdict::Aligned;
  return r;
}

}  // namespace

const char *align_verdict_name(AlignVerdict v) {
  switch (v) {
    case AlignVerdict::Aligned: return "aligned";
    case AlignVerdict::NoOverlap: return "no_overlap";
    case AlignVerdict::Ambiguous: return "ambiguous";
  }
  return "?";
}

AlignMap align_map_of(FinishedMap &&map, const GridGeometry &geo) {
  const carmen::GlobalOffset origin = world_origin(map, geo);
  AlignMap out;
  out.size_x = map.size_x;
  out.size_y = map.size_y;
  out.resolution = map.resolution;
  out.origin_x = origin.x;
  out.origin_y = origin.y;
  out.cells = std::move(map.cells);
  return out;
}

AlignMap align_map_of(const FinishedMap &map, const GridGeometry &geo) { return align_map_of(FinishedMap(map), geo); }

AlignResult align_maps(const AlignMap &reference, const AlignMap &moving, const AlignOptions &options) {
  check_options(options);
  check_map(reference, "reference");
  check_map(moving, "moving");
  const double h = options.match_resolution;
  AlignResult r;
  bool gpu = gpu_chosen(options);  // before any refusal: backend Gpu without a GPU throws whatever the maps
  if (too_large(reference, h) || too_large(moving, h)) {
    std::ostringstream msg;
    msg << "align_maps: a map at the matching cell of " << h << " m would pass " << kMaxSide << " cells a side or "
        << kMaxCells << " cells";
    throw Error(ErrorCode::TooLarge, msg.str());
  }
  if (!(reference.resolution > 0) || !(moving.resolution > 0)) return refused(r, "a map has no positive resolution");
  StageClock clock;
  const Prepared p = prepare(reference, moving, h);
  clock.mark("prepare");
  r.moving_points = static_cast<int>(p.fine.points.size());
  if (p.fine.points.empty()) return refused(r, "the moving map has no wall cell (p > 0.65)");
  if (p.fine.reference_walls == 0) return refused(r, "the reference map has no wall cell (p > 0.65)");
  const int threads = options.threads > 0 ? options.threads : hardware_threads();
  const std::vector<Found> found = search(p, options, threads, &r.rotations, &gpu);
  r.gpu = gpu;
  if (found.empty()) return refused(r, "no candidate scores above 0");
  r.best = found[0].candidate;
  const RefineInput in{&p.fine.field, h, &p.fine.points, p.c_x, p.c_y};
  int on_known = 0;
  count_overlap(in, found[0].placement, &on_known, &r.matched);
  r.overlap = static_cast<double>(on_known) / p.fine.points.size();
  for (size_t i = 1; i < found.size() && !r.has_second; ++i)
    if (distinct(found[i], found[0], p)) {
      r.second = found[i].candidate;
      r.has_second = true;
    }
  return judged(r, options);
}

}  // namespace vasco
