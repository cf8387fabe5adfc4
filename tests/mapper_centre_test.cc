// vasco::Mapper's fixed frame at a given centre (GridGeometry::centre_given):
// the frame stays where it was put whatever the first scan's pose; its grid
// is, bit for bit, that of CARMEN's own egrid API whose first update is a
// pose at the centre without readings (the frame's route in egrid.c, with
// no scan at the centre); inserts in pieces, start_over, render() and the
// restore after a failed call all keep the centre.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <new>
#include <random>
#include <string>
#include <vector>

#include "mapper_centre_support.h"
#include "test_seed.h"
#include "test_support.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/mapper.hpp"

namespace vasco {
namespace {

using testing_support::expect_bit_identical;
using testing_support::first_difference;
using centre_support::anchored_at_centre;
using centre_support::carmen_anchored;
using centre_support::centred_frame;
using centre_support::fr079;
using centre_support::full_resolution;

void expect_centre(const Mapper &m, const GridGeometry &want, const std::string &when) {
  EXPECT_TRUE(m.frame().centre_given) << when;
  EXPECT_EQ(m.frame().x0, want.x0) << when;
  EXPECT_EQ(m.frame().y0, want.y0) << when;
  EXPECT_EQ(m.frame().size_x, want.size_x) << when;
  EXPECT_EQ(m.frame().size_y, want.size_y) << when;
  EXPECT_EQ(m.grid_frame().x0, want.x0) << when;
  EXPECT_EQ(m.grid_frame().y0, want.y0) << when;
}

// A grid with known cells, or equal grids would prove little.
size_t known_cells(const std::vector<float> &cells) {
  size_t n = 0;
  for (float c : cells) n += c != egrid::kUnknown;
  return n;
}

struct ExactCase {
  const char *name;
  const char *backend;
  int threads;
};

class CentredExact : public ::testing::TestWithParam<ExactCase> {
 protected:
  Mapper make(const GridGeometry &frame, const MapperParams &p = full_resolution()) {
    BackendOptions o;
    o.threads = GetParam().threads;
    return Mapper(p, frame, GetParam().backend, o);
  }
};

TEST_P(CentredExact, TheFrameStaysAtTheCentreWhateverTheFirstScan) {
  const GridGeometry frame = centred_frame();
  const MapperParams p = full_resolution();
  for (long first : {0L, 150L, 300L}) {
    const ScanBatch scans = fr079(first, 80);
    Mapper m = make(frame);
    expect_centre(m, frame, "before any insert");
    m.insert(scans);
    expect_centre(m, frame, "first scan " + std::to_string(first));
    const std::vector<float> got = m.read(), want = carmen_anchored(scans, p, frame);
    EXPECT_GT(known_cells(want), 1000u) << "the scans should fall inside the frame";
    expect_bit_identical(want, got, frame, GetParam().name);
    // The frame centred on the first scan (CARMEN's egrid.c) is another grid:
    // the comparison above can fail.
    GridGeometry on_first_scan = frame;
    on_first_scan.centre_given = false;
    Mapper old(p, on_first_scan, GetParam().backend);
    old.insert(scans);
    EXPECT_EQ(old.frame().x0, scans.x[0]);
    EXPECT_LT(first_difference(want, old.read()), want.size()) << "first scan " << first;
  }
}

TEST_P(CentredExact, InsertsInPiecesEqualCarmensApiAnchoredAtTheCentre) {
  const GridGeometry frame = centred_frame();
  const ScanBatch scans = fr079(0, 250);
  std::mt19937 rng(testing_support::test_seed(55));
  std::uniform_int_distribution<long> piece(1, 40);
  Mapper m = make(frame);
  for (long a = 0; a < static_cast<long>(scans.num_scans());) {
    const long n = std::min(piece(rng), static_cast<long>(scans.num_scans()) - a);
    m.insert(scans.select(a, n));
    a += n;
  }
  expect_centre(m, frame, "after the pieces");
  EXPECT_EQ(m.renders(), 1u);  // a fixed frame never grows
  expect_bit_identical(carmen_anchored(scans, m.params(), frame), m.read(), frame, GetParam().name);
}

TEST_P(CentredExact, RenderKeepsTheCentre) {
  const GridGeometry frame = centred_frame();
  const ScanBatch scans = fr079(0, 120);
  Mapper m = make(frame);
  m.insert(scans);
  // Every pose moved 0.8 m west and turned: the first pose moves too, the frame does not.
  ScanBatch moved = scans;
  std::vector<Pose> poses = m.poses();
  for (size_t s = 0; s < poses.size(); ++s) {
    poses[s].x -= 0.8;
    poses[s].theta += 0.05;
    moved.x[s] = poses[s].x;
    moved.theta[s] = poses[s].theta;
  }
  m.render(poses);
  expect_centre(m, frame, "after render");
  expect_bit_identical(carmen_anchored(moved, m.params(), frame), m.read(), frame, GetParam().name);
}

TEST_P(CentredExact, StartOverKeepsTheCentre) {
  const GridGeometry frame = centred_frame();
  Mapper m = make(frame);
  m.insert(fr079(0, 60));
  MapperParams p = full_resolution();
  p.p_occ = 0.6;  // new parameters, the same frame
  m.start_over(p);
  expect_centre(m, frame, "after start_over");
  const ScanBatch next = fr079(200, 60);  // a first scan elsewhere
  m.insert(next);
  expect_centre(m, frame, "after the next insert");
  expect_bit_identical(carmen_anchored(next, p, frame), m.read(), frame, GetParam().name);
}

INSTANTIATE_TEST_SUITE_P(Backends, CentredExact,
                         ::testing::Values(ExactCase{"cpu_double", "cpu_double", 0},
                                           ExactCase{"cpu_threads_3", "cpu_threads", 3}),
                         [](const ::testing::TestParamInfo<ExactCase> &i) { return std::string(i.param.name); });

TEST(MapperCentre, EqualsTheFirstScanFrameWithAScanAtTheCentre) {
  // A route through the Mapper's other fixed frame: a first scan at the
  // centre, heading theta_offset, without readings, then the scans. Every
  // backend, cpu_float included, places the scans from the same start pose.
  const GridGeometry frame = centred_frame();
  const ScanBatch scans = fr079(100, 150);
  const auto [on_first_scan, anchored] = anchored_at_centre(frame, scans);
  for (const char *backend : {"cpu_double", "cpu_threads", "cpu_float"}) {
    Mapper centred(full_resolution(), frame, backend), first_scan(full_resolution(), on_first_scan, backend);
    centred.insert(scans);
    first_scan.insert(anchored);
    ASSERT_EQ(first_scan.frame().x0, frame.x0);
    ASSERT_EQ(first_scan.frame().y0, frame.y0);
    const std::vector<float> want = first_scan.read();
    EXPECT_GT(known_cells(want), 1000u);
    expect_bit_identical(want, centred.read(), frame, backend);
  }
}

TEST(MapperCentre, ThetaOffsetMovesNothing) {
  // With a given centre the grid's axes are the world's: any theta_offset
  // gives the grid of a start pose at the centre heading that same offset.
  const ScanBatch scans = fr079(0, 100);
  const std::vector<float> want = carmen_anchored(scans, full_resolution(), centred_frame(), 0.7);
  for (double t : {0.0, -2.5}) {
    Mapper m(full_resolution(), centred_frame(t), "cpu_double");
    m.insert(scans);
    expect_bit_identical(want, m.read(), centred_frame(), "theta_offset " + std::to_string(t));
  }
}

TEST(MapperCentre, ANonFiniteCentreIsRefused) {
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    GridGeometry f = centred_frame();
    f.y0 = bad;
    try {
      Mapper m(full_resolution(), f, "cpu_double");
      ADD_FAILURE() << "a centre with y0 = " << bad << " was accepted";
    } catch (const Error &e) {
      EXPECT_EQ(e.code(), ErrorCode::Usage);
      EXPECT_NE(std::string(e.what()).find("centre"), std::string::npos) << e.what();
    }
  }
  GridGeometry f = centred_frame();
  f.x0 = std::numeric_limits<double>::infinity();
  f.centre_given = false;  // the first scan's centre: x0 is not read
  EXPECT_NO_THROW(Mapper(full_resolution(), f, "cpu_double"));
}

// cpu_double failing with std::bad_alloc at the chosen applies (after doing
// them: the grid has changed when it throws).
class FailingRenderer : public Renderer {
 public:
  int fail_apply_at = -1;  // 0-based call number; -1: never
  int applies = 0;

  std::string name() const override { return inner_->name(); }
  void reset(const GridGeometry &geo, const MapperParams &params) override { inner_->reset(geo, params); }
  void apply(const ScanBatch &s, size_t first, size_t last, MapStats *stats) override {
    inner_->apply(s, first, last, stats);
    if (applies++ == fail_apply_at) throw std::bad_alloc();
  }
  FinishedMap finish(int ds, int border) override { return inner_->finish(ds, border); }
  std::vector<float> read(const GridWindow &w) override { return inner_->read(w); }
  RendererTraits traits() const override { return inner_->traits(); }

 private:
  std::unique_ptr<Renderer> inner_ = make_renderer("cpu_double");
};

TEST(MapperCentre, FailedCallsKeepTheCentre) {
  const GridGeometry frame = centred_frame();
  const MapperParams p = full_resolution();
  auto owned = std::make_unique<FailingRenderer>();
  FailingRenderer *r = owned.get();
  Mapper m(p, frame, std::move(owned));
  const ScanBatch first = fr079(150, 50), second = fr079(0, 50);
  r->fail_apply_at = 0;  // the first insert fails: nothing stored
  EXPECT_THROW(m.insert(first), std::bad_alloc);
  EXPECT_EQ(m.num_scans(), 0u);
  expect_centre(m, frame, "after a failed first insert");
  m.insert(first);
  r->fail_apply_at = r->applies;  // the next insert fails: the first one's grid rendered again
  EXPECT_THROW(m.insert(second), std::bad_alloc);
  EXPECT_EQ(m.num_scans(), first.num_scans());
  expect_centre(m, frame, "after a failed insert");
  expect_bit_identical(carmen_anchored(first, p, frame), m.read(), frame, "restored");
  ScanBatch both = first;
  both.append(second);
  m.insert(second);
  expect_bit_identical(carmen_anchored(both, p, frame), m.read(), frame, "both inserts");
  r->fail_apply_at = r->applies;  // a render that fails keeps the old poses and the centre
  std::vector<Pose> poses = m.poses();
  for (Pose &q : poses) q.x += 1.5;
  EXPECT_THROW(m.render(poses), std::bad_alloc);
  expect_centre(m, frame, "after a failed render");
  expect_bit_identical(carmen_anchored(both, p, frame), m.read(), frame, "after a failed render");
  // An insert over the budget (68 bytes a beam): refused before anything changes.
  m.set_max_memory_bytes(static_cast<uint64_t>(m.memory_need()) + 68);
  EXPECT_THROW(m.insert(second), Error);
  expect_centre(m, frame, "after an insert over the budget");
  expect_bit_identical(carmen_anchored(both, p, frame), m.read(), frame, "after the refusal");
}

}  // namespace
}  // namespace vasco
