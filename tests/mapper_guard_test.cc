// vasco::Mapper's guarantees against misuse and failure: a batch whose arrays
// disagree, non-finite poses and headings are refused naming the scan; a
// renderer that fails mid-call leaves the session as it was (scans, poses,
// frame, grid); finish takes any border; live insertion grows the frame
// geometrically, and read() and finish() still equal a fresh render in frame().
#include <gtest/gtest.h>

#include <climits>
#include <functional>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "test_support.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/mapper.hpp"

namespace vasco {
namespace {

using testing_support::expect_bit_identical;

// A corridor drive: scan s at x = step * s, 181 beams to walls 2 m away.
ScanBatch drive(size_t n, double step, size_t first = 0) {
  ScanBatch b;
  std::vector<float> r(181);
  for (size_t s = first; s < first + n; ++s) {
    for (int i = 0; i < 181; ++i) {
      const double a = -M_PI / 2 + i * M_PI / 180, sa = std::fabs(std::sin(a));
      r[i] = static_cast<float>(sa > 0.2 ? 2.0 / sa : 10.0);
    }
    b.add_scan(step * s, 0.01 * std::sin(0.3 * s), 0.001 * s, -M_PI / 2, M_PI / 180, r.data(), 181,
               static_cast<long>(s + 1));
  }
  return b;
}

MapperParams small_params() {
  MapperParams p;
  p.resolution = 0.05;
  p.range_max = 4.0;
  p.range_sure = 2.0;
  p.downsample = 1;
  return p;
}

// The whole grid of `scans` in `geo`, rendered afresh by cpu_double.
std::vector<float> fresh(const ScanBatch &scans, const MapperParams &p, const GridGeometry &geo) {
  auto r = make_renderer("cpu_double");
  return render_grid(*r, scans, p, geo, nullptr);
}

FinishedMap fresh_finish(const ScanBatch &scans, const GridGeometry &geo) {
  const std::vector<float> cells = fresh(scans, small_params(), geo);
  return finish_grid(cells.data(), geo.size_x, geo.size_y, geo.resolution, 1, 5);
}

ErrorCode code_of(const std::function<void()> &f) {
  try {
    f();
  } catch (const Error &e) {
    return e.code();
  }
  ADD_FAILURE() << "no vasco::Error thrown";
  return ErrorCode::Internal;
}

std::string message_of(const std::function<void()> &f) {
  try {
    f();
  } catch (const std::exception &e) {
    return e.what();
  }
  return "";
}

// cpu_double, failing with std::bad_alloc at the chosen calls of reset or
// apply (after doing them: the grid has changed when it throws).
class FailingRenderer : public Renderer {
 public:
  int fail_reset_at = -1, fail_apply_at = -1;  // 0-based call numbers; -1: never
  bool fail_every_after = false;               // and every call after the first failure
  int resets = 0, applies = 0;

  std::string name() const override { return inner_->name(); }
  void reset(const GridGeometry &geo, const MapperParams &params) override {
    inner_->reset(geo, params);
    maybe_fail(resets++, fail_reset_at);
  }
  void apply(const ScanBatch &s, size_t first, size_t last, MapStats *stats) override {
    inner_->apply(s, first, last, stats);
    maybe_fail(applies++, fail_apply_at);
  }
  FinishedMap finish(int ds, int border) override { return inner_->finish(ds, border); }
  std::vector<float> read(const GridWindow &w) override { return inner_->read(w); }
  RendererTraits traits() const override { return inner_->traits(); }

 private:
  void maybe_fail(int call, int at) {
    if ((at >= 0 && call == at) || (failed_ && fail_every_after)) {
      failed_ = true;
      throw std::bad_alloc();
    }
  }
  std::unique_ptr<Renderer> inner_ = make_renderer("cpu_double");
  bool failed_ = false;
};

struct Session {
  FailingRenderer *renderer;
  std::unique_ptr<Mapper> mapper;
};

Session failing_session() {
  auto r = std::make_unique<FailingRenderer>();
  Session s{r.get(), nullptr};
  s.mapper = std::make_unique<Mapper>(small_params(), std::move(r));
  return s;
}

void expect_unchanged(const Mapper &m, const ScanBatch &stored, const std::vector<float> &grid,
                      const GridGeometry &geo) {
  ASSERT_EQ(m.num_scans(), stored.num_scans());
  EXPECT_EQ(m.frame().size_x, geo.size_x);
  EXPECT_EQ(m.frame().size_y, geo.size_y);
  EXPECT_EQ(m.scans().range, stored.range);
  EXPECT_EQ(m.scans().x, stored.x);
  expect_bit_identical(grid, m.read(), geo, "after the failed call");
  expect_bit_identical(fresh(stored, m.params(), geo), m.read(), geo, "a fresh render of the stored scans");
}

// A failing session that has mapped 10 scans, and what it held then.
struct Started {
  Session s = failing_session();
  ScanBatch first = drive(10, 0.05);
  std::vector<float> grid;
  GridGeometry geo;
  Started() {
    s.mapper->insert(first);
    grid = s.mapper->read();
    geo = s.mapper->frame();
  }
  void expect_unchanged() const { vasco::expect_unchanged(*s.mapper, first, grid, geo); }
};

TEST(MapperGuard, FailedApplyInTheSameFrameLeavesTheSessionAsItWas) {
  Started t;
  t.s.renderer->fail_apply_at = t.s.renderer->applies;  // the next apply: scans 10..11, same frame
  EXPECT_THROW(t.s.mapper->insert(drive(2, 0.05, 10)), std::bad_alloc);
  t.expect_unchanged();
  EXPECT_EQ(t.s.mapper->finish(1, 5).cells, fresh_finish(t.first, t.geo).cells);
}

TEST(MapperGuard, FailedGrowthRenderLeavesTheSessionAsItWas) {
  Started t;
  t.s.renderer->fail_reset_at = t.s.renderer->resets;  // the growth's reset
  EXPECT_THROW(t.s.mapper->insert(drive(1, 0.05, 400)), std::bad_alloc);  // 20 m out: grows
  t.expect_unchanged();
}

TEST(MapperGuard, FailedRenderKeepsTheOldPoses) {
  Started t;
  std::vector<Pose> moved = t.s.mapper->poses();
  for (Pose &p : moved) p.x += 3.0;
  t.s.renderer->fail_apply_at = t.s.renderer->applies;
  EXPECT_THROW(t.s.mapper->render(moved), std::bad_alloc);
  t.expect_unchanged();
}

TEST(MapperGuard, ALostGridIsRefusedUntilRenderedAgain) {
  Started t;
  t.s.renderer->fail_apply_at = t.s.renderer->applies;
  t.s.renderer->fail_every_after = true;  // the restoring render fails too
  EXPECT_THROW(t.s.mapper->insert(drive(2, 0.05, 10)), std::bad_alloc);
  EXPECT_EQ(t.s.mapper->num_scans(), 10u);
  EXPECT_EQ(code_of([&] { t.s.mapper->finish(); }), ErrorCode::State);
  EXPECT_EQ(code_of([&] { t.s.mapper->read(); }), ErrorCode::State);
}

TEST(MapperGuard, RenderAfterALostGridRestoresIt) {
  auto r = std::make_unique<FailingRenderer>();
  FailingRenderer *fr = r.get();
  Mapper m(small_params(), std::move(r));
  const ScanBatch first = drive(10, 0.05);
  m.insert(first);
  fr->fail_apply_at = fr->applies;
  fr->fail_reset_at = fr->resets;  // the restore's reset fails
  EXPECT_THROW(m.insert(drive(2, 0.05, 10)), std::bad_alloc);
  EXPECT_EQ(code_of([&] { m.finish(); }), ErrorCode::State);
  m.render(m.poses());
  expect_bit_identical(fresh(first, m.params(), m.frame()), m.read(), m.frame(), "rendered again");
}

TEST(MapperGuard, AHugeThreadCountIsRefusedBeforeAnyInsert) {
  // 2^31 - 1 threads used to fail inside an insert after the session changed
  // (and make per-thread scratch of 16 GiB first).
  BackendOptions o;
  for (int threads : {INT_MAX, kMaxThreads + 1, -1}) {
    o.threads = threads;
    EXPECT_EQ(code_of([&] { Mapper m(small_params(), "cpu_threads", o); }), ErrorCode::Usage) << threads;
  }
  o.threads = kMaxThreads;
  Mapper m(small_params(), "cpu_threads", o);
  EXPECT_EQ(m.backend_name(), "cpu_threads");
}

TEST(MapperGuard, OverTheMemoryBudgetIsOutOfMemoryAndChangesNothing) {
  BackendOptions o;
  o.max_memory_bytes = 8u << 20;
  Mapper m(small_params(), "cpu_double", o);
  const ScanBatch first = drive(5, 0.05);
  m.insert(first);
  const std::vector<float> grid = m.read();
  const GridGeometry geo = m.frame();
  EXPECT_EQ(code_of([&] { m.insert(drive(1, 1000.0, 2)); }), ErrorCode::OutOfMemory);  // 2 km out
  expect_unchanged(m, first, grid, geo);
  EXPECT_EQ(code_of([&] { m.set_max_memory_bytes(1024); }), ErrorCode::OutOfMemory);
  EXPECT_EQ(code_of([&] { m.insert(drive(1, 1000.0, 2)); }), ErrorCode::OutOfMemory);  // the budget stayed
  m.set_max_memory_bytes(0);
  m.insert(drive(1, 1000.0, 2));
  EXPECT_EQ(m.num_scans(), 6u);
}

// The MiB figures of a refusal, as the message gives them.
double mib_after(const std::string &m, const std::string &before) {
  const size_t at = m.find(before);
  return at == std::string::npos ? -1 : std::stod(m.substr(at + before.size()));
}

// A refusal always reads as a need above the budget (it said "needs about 2
// MiB ... more than the budget of 2 MiB"), and names how to raise it only
// where the caller said how.
TEST(MapperGuard, AMemoryRefusalReadsAsMoreThanTheBudget) {
  for (uint64_t budget : {uint64_t(2) << 20, uint64_t(3) << 20, (uint64_t(5) << 20) / 2}) {
    BackendOptions o;
    o.max_memory_bytes = budget;
    int refused = 0;
    for (double step = 1.0; step < 400.0; step *= 1.005) {  // grids of growing size around the budget
      Mapper m(small_params(), "cpu_double", o);
      const std::string msg = message_of([&] { m.insert(drive(2, step)); });
      if (msg.empty()) continue;
      ++refused;
      const double need = mib_after(msg, "needs about "), said = mib_after(msg, "the budget of ");
      ASSERT_GT(need, 0) << msg;
      EXPECT_GT(need, said) << msg;
      EXPECT_LE(said * (1 << 20), static_cast<double>(budget)) << msg;
      EXPECT_EQ(msg.find("raise it"), std::string::npos) << msg;
    }
    EXPECT_GT(refused, 3) << budget;
  }
  BackendOptions o;
  o.max_memory_bytes = 1 << 20;
  o.budget_hint = "--max-memory MiB";
  Mapper m(small_params(), "cpu_double", o);
  EXPECT_NE(message_of([&] { m.insert(drive(2, 200.0)); }).find("raise it (--max-memory MiB)"), std::string::npos);
}

// A batch of three scans, broken by `breakit`, must be refused naming `scan`
// by insert, and when its arrays disagree (not only a pose) by select and
// checked_ranges_of too.
void expect_refused(const std::function<void(ScanBatch &)> &breakit, const std::string &scan,
                    bool arrays = true) {
  ScanBatch b = drive(3, 0.05);
  breakit(b);
  Mapper m(small_params());
  EXPECT_EQ(code_of([&] { m.insert(b); }), ErrorCode::BadInput) << scan;
  EXPECT_NE(message_of([&] { m.insert(b); }).find(scan), std::string::npos) << message_of([&] { m.insert(b); });
  EXPECT_EQ(m.num_scans(), 0u);
  if (!arrays) return;
  EXPECT_EQ(code_of([&] { b.select(0, -1); }), ErrorCode::BadInput);
  EXPECT_EQ(code_of([&] { b.checked_ranges_of(0); }), ErrorCode::BadInput);
}

TEST(MapperGuard, BatchesWhoseArraysDisagreeAreRefusedNamingTheScan) {
  expect_refused([](ScanBatch &b) { b.beam_offset[1] = 1 << 20; }, "scan 1");  // decreasing after
  expect_refused([](ScanBatch &b) { b.beam_offset.back() = 10000000; }, "scan 2");
  expect_refused([](ScanBatch &b) { b.beam_offset[0] = 5; }, "scan 0");
  expect_refused([](ScanBatch &b) { b.y.pop_back(); }, "scan 2");
  expect_refused([](ScanBatch &b) { b.theta.push_back(0); }, "scan 3");
  expect_refused([](ScanBatch &b) { b.line.clear(); }, "scan 0");
  expect_refused([](ScanBatch &b) { b.beam_offset.pop_back(); }, "scan 2");
  expect_refused([](ScanBatch &b) { b.range.pop_back(); }, "scan 2");
  expect_refused([](ScanBatch &b) { b.x[1] = std::nan(""); }, "scan 1", false);
  expect_refused([](ScanBatch &b) { b.theta[2] = INFINITY; }, "scan 2", false);
  expect_refused([](ScanBatch &b) { b.y[0] = -INFINITY; }, "scan 0", false);
  // A non-finite beam angle was mapped (the map doubled in width): refused like a pose.
  expect_refused([](ScanBatch &b) { b.first_angle[1] = std::nan(""); }, "scan 1: the first beam's angle", false);
  expect_refused([](ScanBatch &b) { b.angle_step[2] = INFINITY; }, "scan 2: the angle step", false);
  expect_refused([](ScanBatch &b) { b.first_angle[0] = -INFINITY; }, "scan 0", false);
  EXPECT_EQ(code_of([] { drive(2, 0.1).checked_ranges_of(2); }), ErrorCode::Usage);
}

TEST(MapperGuard, NonFinitePosesAndHeadingsAreRefused) {
  Mapper m(small_params());
  const ScanBatch first = drive(4, 0.05);
  m.insert(first);
  const std::vector<float> grid = m.read();
  std::vector<Pose> poses = m.poses();
  poses[1].theta = std::nan("");
  EXPECT_EQ(code_of([&] { m.render(poses); }), ErrorCode::BadInput);
  EXPECT_NE(message_of([&] { m.render(poses); }).find("pose 1"), std::string::npos);
  poses[1].theta = 0;
  poses[3].x = INFINITY;
  EXPECT_NE(message_of([&] { m.render(poses); }).find("pose 3"), std::string::npos);
  expect_unchanged(m, first, grid, m.frame());
  GridGeometry frame;
  frame.size_x = frame.size_y = 100;
  frame.resolution = small_params().resolution;
  frame.theta_offset = std::nan("");
  EXPECT_EQ(code_of([&] { Mapper f(small_params(), frame, "cpu_double"); }), ErrorCode::Usage);
  frame.theta_offset = INFINITY;
  EXPECT_EQ(code_of([&] { Mapper f(small_params(), frame, "cpu_double"); }), ErrorCode::Usage);
}

TEST(MapperGuard, FinishTakesAnyBorderWithoutOverflow) {
  Mapper m(small_params());
  m.insert(drive(5, 0.05));
  const GridGeometry geo = m.frame();
  for (int border : {INT_MAX, INT_MAX - 1, INT_MAX / 2, 1 << 30}) {
    // Every bound clamps to the grid: blocks 0 .. n - 1, size n - 1 (CARMEN's missing +1).
    const FinishedMap f = m.finish(2, border);
    EXPECT_EQ(f.min_x, 0);
    EXPECT_EQ(f.min_y, 0);
    EXPECT_EQ(f.size_x, geo.size_x / 2 - 1) << border;
    EXPECT_EQ(f.size_y, geo.size_y / 2 - 1) << border;
  }
  EXPECT_EQ(m.finish(geo.size_x, INT_MAX).size_x, 0);
  EXPECT_EQ(code_of([&] { m.finish(0, 1); }), ErrorCode::Usage);
  EXPECT_EQ(code_of([&] { m.finish(1, -1); }), ErrorCode::Usage);
  EXPECT_EQ(code_of([&] { Mapper(small_params()).finish(); }), ErrorCode::State);
}

// A robot driving straight out, one scan per insert.
void drive_out(Mapper &m, size_t n, double step) {
  for (size_t s = 0; s < n; ++s) m.insert(drive(1, step, s));
}

TEST(MapperGuard, DrivingOutCostsLogarithmicallyManyRenders) {
  for (const char *backend : {"cpu_double", "cpu_threads"}) {
    BackendOptions o;
    o.threads = 3;
    Mapper m(small_params(), backend, o);
    drive_out(m, 200, 0.1);  // 20 m: the first frame is 4 m from the start each way
    // One render per growth by 1.5x from about 4.05 m to 24.05 m: 5, and the
    // first insert. One growth per insert (the old rule) would be ~200.
    EXPECT_LE(m.renders(), 7u) << backend;
    const std::vector<float> want = fresh(m.scans(), m.params(), m.frame());
    expect_bit_identical(want, m.read(), m.frame(), backend);
    const GridGeometry protocol = size_grid(m.scans(), m.params());  // frame() is it, margin unseen
    EXPECT_EQ(m.frame().size_x, protocol.size_x);
    EXPECT_EQ(m.frame().size_y, protocol.size_y);
    const FinishedMap f = m.finish(2, 7);
    EXPECT_EQ(f.cells, finish_grid(want.data(), protocol.size_x, protocol.size_y, protocol.resolution, 2, 7).cells);
  }
  Mapper longer(small_params());
  drive_out(longer, 400, 0.1);
  EXPECT_LE(longer.renders(), 8u) << "twice the inserts, at most two more renders";
}

TEST(MapperGuard, MovingInsertTakesTheArraysAndGivesThemBackOnFailure) {
  Mapper m(small_params());
  ScanBatch b = drive(5, 0.05);
  const ScanBatch copy = b;
  m.insert(std::move(b));
  EXPECT_EQ(m.scans().range, copy.range);
  expect_bit_identical(fresh(copy, m.params(), m.frame()), m.read(), m.frame(), "moved in");
  BackendOptions tiny;
  tiny.max_memory_bytes = 1024;
  Mapper refused(small_params(), "cpu_double", tiny);
  ScanBatch c = copy;
  EXPECT_EQ(code_of([&] { refused.insert(std::move(c)); }), ErrorCode::OutOfMemory);
  EXPECT_EQ(c.range, copy.range) << "a refused batch stays the caller's";
}

TEST(MapperGuard, MovingSelectEqualsCopyingSelect) {
  const ScanBatch b = drive(9, 0.05);
  for (long first : {0L, 2L, 8L, 20L})
    for (long count : {-1L, 0L, 3L, 100L}) {
      const ScanBatch copied = b.select(first, count);
      ScanBatch moved = ScanBatch(b).select(first, count);
      EXPECT_EQ(moved.range, copied.range);
      EXPECT_EQ(moved.beam_offset, copied.beam_offset);
      EXPECT_EQ(moved.x, copied.x);
      EXPECT_EQ(moved.line, copied.line);
      moved.validate();
    }
}

}  // namespace
}  // namespace vasco
