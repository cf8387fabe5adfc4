// float_golden_support.h — the float paths (cpu_float, CUDA float mode)
// measured against CARMEN's golden maps with the DESIGN §4 table, and the
// bounds they are held to.
//
// The reference is CARMEN's map itself: cpu_double's map once its GRIDMAP
// digest has been checked equal to the golden digest (the golden files carry
// no crop offset, cpu_double's finish does, which lets two differently cropped
// maps be compared cell for cell).
//
// What single precision can change, and so what the bounds are.
//  1. Where beams run. (CUDA float mode; cpu_float walks the oracle's own
//     beams and cells, so for it (1) and (2) change nothing.) CUDA float
//     places poses, accumulates beam angles and takes cos/sin in float. Over a 361-beam scan the accumulated angle
//     is off by up to about 361 * ulp(pi) / 2 = 4e-5 rad, which at the
//     range_max cut (<= 400 cells here) moves a beam by up to 0.02 cell; the
//     pose itself by 2^-11 cell. A Bresenham cell changes only where the ideal
//     line passes within that of a cell's decision boundary, so about
//     2 * 0.02 = 4 % of cell updates may land one cell over, or turn between
//     free and occupied at a beam's hit. Each such change moves one cell's
//     log-odds by one update (|l(occ)| + |l(emp)|: 0.4 with vasco's 0.55/0.45,
//     3.0 with the paper's 0.9/0.3).
//  2. Known or unknown. Only (1) can change it, and only for a cell that every
//     one of its updates reaches through a moved beam: a fringe cell seen once
//     or twice. Fringe cells are a small part of the known area and 4 % of
//     them at most change, so we allow 1 in 1000 known cells.
//  3. Values. Both float paths add log-odds increments rounded to float
//     (cpu_float: 2^-24 relative; CUDA: to 2^-24 log-odds): about 1e-7 per
//     update, far below one update's step. CUDA sums them in fixed point,
//     exactly; cpu_float in float per call, each add off by at most 2^-24 of
//     the running sum, so n updates of size <= t are off by at most
//     n^2 2^-24 t: below 0.4 in log-odds (p moved by 0.1 near 0.5) while
//     n < 1,700 updates of the cell in one call at the paper's t = 2.2, and
//     n < 5,700 at vasco's t = 0.2. So on its own rounding does not move a
//     cell's class or its p by 0.1 but in a cell updated thousands of times
//     in one call, which the evidence has pushed to 0 or 1 unless its
//     updates nearly cancel. It can however decide when a cell
//     saturates: CARMEN stores exactly 0 or 1 once 1 - 1/(1+t) rounds there,
//     and a saturated cell never moves again (odds 0 or inf), while the other
//     path's cell keeps moving. So max |dp| is not bounded below 1, and with the
//     paper's sharp evidence most cells saturate (3/4 of fr079's known cells).
//  4. So |dp| > 0.1 and a change of class come from (1) near p = 0.5 or at few
//     updates, and from (3) where a cell saturated in one path. (1) touches at
//     most 4 % of updates, and a cell's p moves by 0.1 from one update only if
//     it has few others; saturated cells that flip need the other path to run
//     against a long run of updates. We allow 1 % of the cells known in both
//     for each, and 99 % agreement on the class of the cells CARMEN
//     has occupied or free, which still fails on the defects
//     that matter: a lost update, a misplaced scan or a wrong sensor model
//     change most cells along every beam.
// Cells exactly at 0.5 in CARMEN's map (even: one occupied and one free update
// of vasco's symmetric evidence cancel exactly) count as a class change as soon
// as float rounding leaves them a hair off; they are part of the 1 %.
#ifndef VASCO_TESTS_FLOAT_GOLDEN_SUPPORT_H
#define VASCO_TESTS_FLOAT_GOLDEN_SUPPORT_H

#include <cstdio>

#include "golden_support.h"

namespace vasco {
namespace golden {

constexpr double kMaxStatusDiffersPerKnown = 1e-3;
constexpr double kMaxLargeDiffsPerBothKnown = 1e-2;
constexpr double kMinClassAgreement = 0.99;

inline void expect_float_within_bounds(const Case &c, const Path &path) {
  const std::string log = find_log(c.log, {carried_dir(), std::string(VASCO_LOGS_DIR)});
  ASSERT_FALSE(log.empty()) << "no log for " << c.name;
  const LogInput in = load_case(log, carried_dir() + "/params/" + c.params + ".ini");
  const FinishedMap ref = backend_path("cpu_double", "cpu_double").run(in);
  ASSERT_EQ(digest(ref), c.sha256) << "cpu_double is not CARMEN's map: no reference for " << path.name;
  const FinishedMap got = path.run(in);
  const carmen::Agreement a = compare_finished(ref, got);
  std::printf("%s", a.table(path.name + " vs CARMEN's " + c.name).c_str());
  uint64_t known = 0;
  for (float v : ref.cells) known += v != -1.0f;
  EXPECT_LE(double(a.status_differs), kMaxStatusDiffersPerKnown * double(known)) << c.name;
  EXPECT_LE(double(a.large_diffs), kMaxLargeDiffsPerBothKnown * double(a.both_known)) << c.name;
  // Class agreement over the cells CARMEN classes occupied or free.
  const double classed = double(a.occupied_ref + a.free_ref);
  const double agree = classed > 0 ? double(a.occupied_agree + a.free_agree) / classed : 1.0;
  std::printf("  occupied/free class agreement %.4f %%\n", 100.0 * agree);
  EXPECT_GE(agree, kMinClassAgreement) << c.name;
  EXPECT_LE(a.max_abs_diff, 1.0) << c.name << ": a probability outside [0, 1]";
}

}  // namespace golden
}  // namespace vasco

#endif  // VASCO_TESTS_FLOAT_GOLDEN_SUPPORT_H
