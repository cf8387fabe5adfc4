// vasco::Mapper on the GPU: the CUDA renderer keeps grid, ranges and scratch
// on the device. Exact mode: inserts in pieces and renders with new poses
// equal cpu_double bit for bit; both modes: the finish on the device equals
// CARMEN's finish of the grid read back. Skips without a GPU.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>

#include "golden_support.h"
#include "test_seed.h"
#include "test_support.h"
#include "vasco_gpu/mapper.hpp"

namespace vasco {
namespace {

using testing_support::bundled_log;

class MapperCuda : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (!golden::cuda_available(&why)) GTEST_SKIP() << "no usable GPU: " << why;
    params_.downsample = 1;
    LogLoadStats st;
    scans_ = load_scans(bundled_log("fr079-complete.gfs.log.gz"), params_, carmen::LogReaderOptions{}, &st)
                 .select(0, 700);
  }
  static BackendOptions mode(CudaMode m) {
    BackendOptions o;
    o.cuda_mode = m;
    return o;
  }
  MapperParams params_;
  ScanBatch scans_;
};

TEST_F(MapperCuda, ExactInsertsInPiecesEqualCpuDouble) {
  Mapper m(params_, "cuda", mode(CudaMode::Exact));
  ASSERT_EQ(m.backend_name(), "cuda_exact");
  std::mt19937 rng(testing_support::test_seed(11));
  std::uniform_int_distribution<int> piece(1, 60);
  for (size_t a = 0; a < scans_.num_scans();) {
    const size_t n = std::min<size_t>(piece(rng), scans_.num_scans() - a);
    m.insert(scans_.select(static_cast<long>(a), static_cast<long>(n)));
    a += n;
  }
  const GridGeometry geo = size_grid(scans_, params_);
  const auto ref = make_cpu_double_backend()->map(scans_, params_, geo, nullptr);
  testing_support::expect_bit_identical(ref, m.read(), geo, "cuda exact session");
}

TEST_F(MapperCuda, ExactRenderWithMovedPosesEqualsCpuDouble) {
  Mapper m(params_, "cuda", mode(CudaMode::Exact));
  m.insert(scans_);
  std::vector<Pose> poses = m.poses();
  const Pose pivot = poses[350];
  const double a = 2.0 * M_PI / 180.0;
  for (size_t i = 350; i < poses.size(); ++i) {
    const double dx = poses[i].x - pivot.x, dy = poses[i].y - pivot.y;
    poses[i] = {pivot.x + std::cos(a) * dx - std::sin(a) * dy, pivot.y + std::sin(a) * dx + std::cos(a) * dy,
                poses[i].theta + a};
  }
  m.render(poses);
  m.render(poses);  // twice: a render starts from scratch
  ScanBatch moved = scans_;
  for (size_t i = 0; i < poses.size(); ++i) {
    moved.x[i] = poses[i].x;
    moved.y[i] = poses[i].y;
    moved.theta[i] = poses[i].theta;
  }
  const GridGeometry geo = size_grid(moved, params_);
  const auto ref = make_cpu_double_backend()->map(moved, params_, geo, nullptr);
  testing_support::expect_bit_identical(ref, m.read(), geo, "cuda exact render");
  const FinishedMap host = finish_grid(ref.data(), geo.size_x, geo.size_y, geo.resolution, 4, 20);
  EXPECT_EQ(golden::digest(m.finish(4, 20)), golden::digest(host));
}

TEST_F(MapperCuda, FinishOnTheDeviceEqualsCarmensFinishOfTheGrid) {
  for (CudaMode md : {CudaMode::Float, CudaMode::Exact}) {
    Mapper m(params_, "cuda", mode(md));
    m.insert(scans_);
    const std::vector<float> grid = m.read();
    for (int ds : {1, 3, 4}) {
      const FinishedMap host = finish_grid(grid.data(), m.frame().size_x, m.frame().size_y,
                                           m.frame().resolution, ds, 20);
      const FinishedMap dev = m.finish(ds, 20);
      EXPECT_EQ(dev.min_x, host.min_x);
      EXPECT_EQ(dev.min_y, host.min_y);
      EXPECT_EQ(golden::digest(dev), golden::digest(host)) << m.backend_name() << " downsample " << ds;
    }
    const GridWindow w{100, 200, 33, 17};
    const std::vector<float> win = m.read(w);
    for (int x = 0; x < w.width; ++x)
      for (int y = 0; y < w.height; ++y)
        ASSERT_EQ(win[static_cast<size_t>(x) * w.height + y],
                  grid[static_cast<size_t>(w.x0 + x) * m.frame().size_y + w.y0 + y]);
  }
}

// Float mode sums fixed-point log-odds with integer atomics, so neither the
// order of the adds (which the GPU picks anew on every run) nor the split of
// the scans into inserts changes a bit. (With float atomics, three runs of
// fr079 gave three different maps.)
TEST_F(MapperCuda, FloatSessionIsTheSameBytesWhateverTheRunAndTheInserts) {
  Mapper once(params_, "cuda", mode(CudaMode::Float));
  once.insert(scans_);
  const std::vector<float> first = once.read();
  const GridGeometry geo = size_grid(scans_, params_);
  for (int run = 0; run < 3; ++run) {
    Mapper again(params_, "cuda", mode(CudaMode::Float));
    again.insert(scans_);
    testing_support::expect_bit_identical(first, again.read(), geo, "float run " + std::to_string(run));
    again.render(again.poses());
    testing_support::expect_bit_identical(first, again.read(), geo, "float re-render " + std::to_string(run));
  }
  Mapper pieces(params_, "cuda", mode(CudaMode::Float));
  for (size_t a = 0; a < scans_.num_scans(); a += 50) pieces.insert(scans_.select(static_cast<long>(a), 50));
  testing_support::expect_bit_identical(first, pieces.read(), geo, "float inserts of 50 scans");
}

// Both modes look updates up in per-(i, j) tables when the table is small
// enough and compute them in full otherwise (VASCO_CUDA_NO_TABLES forces the
// latter): the two must agree bit for bit, and exact mode with cpu_double.
TEST_F(MapperCuda, TablesChangeNoBitInEitherMode) {
  const GridGeometry geo = size_grid(scans_, params_);
  for (CudaMode cm : {CudaMode::Float, CudaMode::Exact}) {
    Mapper tabled(params_, "cuda", mode(cm));
    tabled.insert(scans_);
    ASSERT_EQ(setenv("VASCO_CUDA_NO_TABLES", "1", 1), 0);
    Mapper computed(params_, "cuda", mode(cm));
    computed.insert(scans_);
    unsetenv("VASCO_CUDA_NO_TABLES");
    testing_support::expect_bit_identical(tabled.read(), computed.read(), geo,
                                          cm == CudaMode::Float ? "float, tables vs none" : "exact, tables vs none");
  }
}

// Float mode sums in fixed point: a log whose beams could push a cell past
// its range (here: evidence 0.999999, 13.8 log-odds a beam, so about 300,000
// beams) is refused before anything changes, by insert and by render alike.
TEST_F(MapperCuda, FloatRefusesBeamsPastItsFixedPointRangeAndChangesNothing) {
  MapperParams sharp = params_;
  sharp.p_occ = 0.999999;
  Mapper m(sharp, "cuda", mode(CudaMode::Float));
  m.insert(scans_.select(0, 100));
  const std::vector<float> before = m.read();
  const std::vector<Pose> poses = m.poses();
  ScanBatch many;
  for (int rep = 0; rep < 1000; ++rep)
    many.add_scan(scans_.x[0], scans_.y[0], scans_.theta[0], scans_.first_angle[0], scans_.angle_step[0],
                  scans_.ranges_of(0), scans_.beams_in(0), rep + 1);
  try {
    m.insert(many);
    FAIL() << "inserting " << many.num_beams() << " beams of evidence 0.999999 was accepted";
  } catch (const std::runtime_error &e) {
    EXPECT_NE(std::string(e.what()).find("fixed-point range"), std::string::npos) << e.what();
  }
  EXPECT_EQ(m.poses().size(), poses.size());
  testing_support::expect_bit_identical(before, m.read(), m.frame(), "after the refused insert");
  m.render(poses);  // still renders
  testing_support::expect_bit_identical(before, m.read(), m.frame(), "after a render");
}

}  // namespace
}  // namespace vasco
