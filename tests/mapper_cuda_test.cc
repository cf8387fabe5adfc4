// vasco::Mapper on the GPU: the CUDA renderer keeps grid, ranges and scratch
// on the device. Exact mode: inserts in pieces and renders with new poses
// equal cpu_double bit for bit; both modes: the finish on the device equals
// CARMEN's finish of the grid read back, a refused insert or render changes
// nothing, a renderer given a stream works on it and leaves it alive. Skips
// without a GPU.
#include <gtest/gtest.h>

#include <algorithm>

#include <climits>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <random>

#if defined(VASCO_HAVE_CUDA)
#include <cuda_runtime.h>
#endif

#include "golden_support.h"
#include "test_seed.h"
#include "test_support.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/mapper.hpp"

namespace vasco {
namespace {

using testing_support::bundled_log;

#if defined(VASCO_HAVE_CUDA)
// Takes all but `leave` bytes of the GPU's free memory while it lives, so
// that a grown frame cannot fit.
class GpuMemoryHog {
 public:
  explicit GpuMemoryHog(size_t leave) {
    size_t free_b = 0, total_b = 0;
    if (cudaMemGetInfo(&free_b, &total_b) != cudaSuccess || free_b <= leave) return;
    if (cudaMalloc(&ptr_, free_b - leave) != cudaSuccess) {
      ptr_ = nullptr;
      cudaGetLastError();  // clear it: the renderer's next call must not see it
    }
  }
  ~GpuMemoryHog() {
    if (ptr_ != nullptr) cudaFree(ptr_);
  }
  GpuMemoryHog(const GpuMemoryHog &) = delete;
  GpuMemoryHog &operator=(const GpuMemoryHog &) = delete;
  bool holding() const { return ptr_ != nullptr; }

 private:
  void *ptr_ = nullptr;
};
#endif

// What a session shows of itself: the scans, frame, poses, grid and finished map.
struct SessionView {
  size_t scans = 0;
  GridGeometry frame;
  std::vector<Pose> poses;
  std::vector<float> grid;
  std::string finished;
};

SessionView view_of(const Mapper &m) {
  return {m.num_scans(), m.frame(), m.poses(), m.read(), golden::digest(m.finish(4, 20))};
}

[[maybe_unused]] void expect_same_session(const SessionView &before, const Mapper &m, const std::string &what) {
  SCOPED_TRACE(what);
  const SessionView now = view_of(m);
  EXPECT_EQ(now.scans, before.scans);
  EXPECT_EQ(now.frame.size_x, before.frame.size_x);
  EXPECT_EQ(now.frame.size_y, before.frame.size_y);
  EXPECT_EQ(now.frame.x0, before.frame.x0);
  EXPECT_EQ(now.frame.y0, before.frame.y0);
  ASSERT_EQ(now.poses.size(), before.poses.size());
  for (size_t i = 0; i < now.poses.size(); ++i) {
    EXPECT_EQ(now.poses[i].x, before.poses[i].x) << "pose " << i;
    EXPECT_EQ(now.poses[i].y, before.poses[i].y) << "pose " << i;
    EXPECT_EQ(now.poses[i].theta, before.poses[i].theta) << "pose " << i;
  }
  EXPECT_EQ(now.finished, before.finished);
  testing_support::expect_bit_identical(before.grid, now.grid, before.frame, what);
}

// `call` must throw vasco::Error with `code`.
[[maybe_unused]] void expect_error(ErrorCode code, const std::function<void()> &call, const std::string &what) {
  try {
    call();
    ADD_FAILURE() << what << " was accepted";
  } catch (const Error &e) {
    EXPECT_EQ(e.code(), code) << what << ": " << e.what();
  }
}

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
  // Growth leaves a margin: the reference is a fresh map in the session's frame.
  const GridGeometry geo = m.frame();
  const auto ref = render_grid(*make_renderer("cpu_double"), scans_, params_, geo);
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
  const auto ref = render_grid(*make_renderer("cpu_double"), moved, params_, geo);
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

// A grown grid (the frame a window of it) is finished on the device from a
// copy of the window: CARMEN's finish of the frame's cells as read() gives
// them, finished on the host, in either mode and at every downsample.
TEST_F(MapperCuda, GrownGridFinishesTheFramesWindowAsTheHostDoes) {
  for (CudaMode md : {CudaMode::Float, CudaMode::Exact}) {
    Mapper grown(params_, "cuda", mode(md));
    for (size_t a = 0; a < scans_.num_scans(); a += 70) grown.insert(scans_.select(static_cast<long>(a), 70));
    ASSERT_NE(grown.grid_frame().size_x, grown.frame().size_x) << "the grid did not grow: the case is not tested";
    const GridGeometry geo = grown.frame();
    const std::vector<float> cells = grown.read();
    for (int ds : {1, 3, 4}) {
      const FinishedMap host = finish_grid(cells.data(), geo.size_x, geo.size_y, geo.resolution, ds, 20);
      const FinishedMap dev = grown.finish(ds, 20);
      EXPECT_EQ(dev.min_x, host.min_x);
      EXPECT_EQ(dev.min_y, host.min_y);
      EXPECT_EQ(golden::digest(dev), golden::digest(host)) << grown.backend_name() << " grown, downsample " << ds;
    }
  }
}

// finish as OccupancyGrid data, converted on the device: the host's
// conversion of the finish, in either mode; in a grown grid (finished on the
// device from a copy of the frame's window) too.
TEST_F(MapperCuda, FinishOccupancyOnTheDeviceIsTheHostsConversion) {
  for (CudaMode md : {CudaMode::Float, CudaMode::Exact}) {
    Mapper m(params_, "cuda", mode(md));
    m.insert(scans_);
    for (int ds : {1, 3}) testing_support::expect_occupancy_of_finish(m, ds, 20, m.backend_name());
    testing_support::expect_occupancy_of_finish(m, 1, 0, m.backend_name() + " border 0");
    Mapper grown(params_, "cuda", mode(md));
    for (size_t a = 0; a < scans_.num_scans(); a += 70)
      grown.insert(scans_.select(static_cast<long>(a), 70));
    ASSERT_NE(grown.grid_frame().size_x, grown.frame().size_x) << "the grid did not grow: the case is not tested";
    testing_support::expect_occupancy_of_finish(grown, 1, 20, grown.backend_name() + " grown");
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
  // In one frame the integer sums give the same bytes however the scans are
  // split: a fixed frame, fed in pieces of 50.
  Mapper whole(params_, geo, "cuda", mode(CudaMode::Float));
  whole.insert(scans_);
  Mapper pieces(params_, geo, "cuda", mode(CudaMode::Float));
  for (size_t a = 0; a < scans_.num_scans(); a += 50) pieces.insert(scans_.select(static_cast<long>(a), 50));
  testing_support::expect_bit_identical(whole.read(), pieces.read(), geo, "float inserts of 50 scans");
  // A session that grew (its grid has a margin, where a scan may round one
  // cell over: mapper.hpp) is the one-shot map again once rendered anew.
  Mapper grown(params_, "cuda", mode(CudaMode::Float));
  for (size_t a = 0; a < scans_.num_scans(); a += 50) grown.insert(scans_.select(static_cast<long>(a), 50));
  EXPECT_GT(grown.renders(), 1u);
  grown.render(grown.poses());
  testing_support::expect_bit_identical(first, grown.read(), geo, "float inserts of 50 scans, rendered again");
}

// start_over keeps the renderer (its context, scratch, and in float mode
// the ranges it sent): the next log's map must be a fresh Mapper's, in
// both modes. Float mode once kept the first log's ranges on the device
// and mapped the second log's beams with them.
TEST_F(MapperCuda, StartOverMapsTheNextLogAsAFreshMapperInEitherMode) {
  const ScanBatch first = scans_.select(0, 350), second = scans_.select(350, 350);
  for (CudaMode cm : {CudaMode::Float, CudaMode::Exact}) {
    SCOPED_TRACE(cm == CudaMode::Float ? "float" : "exact");
    Mapper m(params_, "cuda", mode(cm));
    m.insert(first);
    m.start_over(params_);
    m.insert(second);
    Mapper fresh(params_, "cuda", mode(cm));
    fresh.insert(second);
    testing_support::expect_bit_identical(fresh.read(), m.read(), fresh.frame(), m.backend_name() + " after start_over");
    EXPECT_EQ(golden::digest(m.finish()), golden::digest(fresh.finish()));
  }
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

// Float mode adds the beams that step along x into a y-major accumulator on a
// render of many scans (VASCO_CUDA_NO_ACROSS forces the x-major sums alone),
// and one insert at a time never uses it: all three must be the same bytes.
TEST_F(MapperCuda, FloatAcrossAccumulatorChangesNoBit) {
  ASSERT_GE(scans_.num_scans(), 256u) << "the test log must be a render of many scans";
  const GridGeometry geo = size_grid(scans_, params_);
  Mapper across(params_, geo, "cuda", mode(CudaMode::Float));
  across.insert(scans_);
  ASSERT_EQ(setenv("VASCO_CUDA_NO_ACROSS", "1", 1), 0);
  Mapper plain(params_, geo, "cuda", mode(CudaMode::Float));
  plain.insert(scans_);
  unsetenv("VASCO_CUDA_NO_ACROSS");
  Mapper one_by_one(params_, geo, "cuda", mode(CudaMode::Float));
  const long n = static_cast<long>(scans_.num_scans());
  for (long s = 0; s < n; s += 97) one_by_one.insert(scans_.select(s, std::min(97L, n - s)));
  testing_support::expect_bit_identical(across.read(), plain.read(), geo, "float, across vs x-major only");
  testing_support::expect_bit_identical(across.read(), one_by_one.read(), geo, "float, one render vs inserts");
  EXPECT_EQ(across.last_stats().cell_updates, plain.last_stats().cell_updates);
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
  } catch (const Error &e) {
    EXPECT_EQ(e.code(), ErrorCode::TooLarge) << e.what();
    EXPECT_NE(std::string(e.what()).find("fixed-point range"), std::string::npos) << e.what();
  }
  EXPECT_EQ(m.poses().size(), poses.size());
  testing_support::expect_bit_identical(before, m.read(), m.frame(), "after the refused insert");
  m.render(poses);  // still renders
  testing_support::expect_bit_identical(before, m.read(), m.frame(), "after a render");
}

// A frame grown beyond the GPU's free memory is refused by the renderer's
// reset before it changes anything: the session keeps its scans, frame,
// poses, grid and finished map, in both modes and for insert and render
// alike, and its later inserts give the bytes of a session that never saw
// the refused calls.
TEST_F(MapperCuda, RefusedGrowthChangesNothingInEitherMode) {
#if defined(VASCO_HAVE_CUDA)
  for (CudaMode md : {CudaMode::Float, CudaMode::Exact}) {
    SCOPED_TRACE(md == CudaMode::Float ? "float" : "exact");
    Mapper m(params_, "cuda", mode(md));
    m.insert(scans_.select(0, 100));
    const SessionView before = view_of(m);
    // 150 m away in x and y: a frame of about 12,800^2 cells (650 MB exact,
    // 1.3 GB float), more than the 512 MiB left free.
    ScanBatch far;
    far.add_scan(scans_.x[0] + 150, scans_.y[0] + 150, scans_.theta[0], scans_.first_angle[0],
                 scans_.angle_step[0], scans_.ranges_of(0), scans_.beams_in(0), 1);
    std::vector<Pose> moved = m.poses();
    moved.back().x += 150;
    moved.back().y += 150;
    {
      GpuMemoryHog hog(size_t(512) << 20);
      ASSERT_TRUE(hog.holding());
      expect_error(ErrorCode::OutOfMemory, [&] { m.insert(far); }, "an insert needing a grown frame");
      expect_same_session(before, m, "after the refused insert");
      expect_error(ErrorCode::OutOfMemory, [&] { m.render(moved); }, "a render needing a grown frame");
      expect_same_session(before, m, "after the refused render");
    }
    m.insert(scans_.select(100, 100));
    Mapper clean(params_, "cuda", mode(md));
    clean.insert(scans_.select(0, 100));
    clean.insert(scans_.select(100, 100));
    expect_same_session(view_of(clean), m, "later inserts");
  }
#endif
}

// The renderer itself, without a session's rollback: a reset refused for
// GPU memory keeps the old frame and grid (read, finish and a further apply
// see them), in both modes.
TEST_F(MapperCuda, RefusedResetKeepsTheRenderersGrid) {
#if defined(VASCO_HAVE_CUDA)
  const GridGeometry geo = size_grid(scans_.select(0, 100), params_);
  GridGeometry huge = geo;
  huge.size_x = huge.size_y = 16384;  // 1 GiB exact, 2 GiB float
  const GridWindow all{0, 0, geo.size_x, geo.size_y};
  for (CudaMode md : {CudaMode::Float, CudaMode::Exact}) {
    std::unique_ptr<Renderer> r = make_cuda_renderer(mode(md));
    r->reset(geo, params_);
    r->apply(scans_, 0, 100, nullptr);
    const std::vector<float> before = r->read(all);
    const std::string finished = golden::digest(r->finish(4, 20));
    {
      GpuMemoryHog hog(size_t(512) << 20);
      ASSERT_TRUE(hog.holding());
      expect_error(ErrorCode::OutOfMemory, [&] { r->reset(huge, params_); }, r->name() + ": a reset past the GPU");
      testing_support::expect_bit_identical(before, r->read(all), geo, r->name() + " after the refused reset");
      EXPECT_EQ(golden::digest(r->finish(4, 20)), finished) << r->name();
    }
    r->apply(scans_, 100, 200, nullptr);
    std::unique_ptr<Renderer> clean = make_cuda_renderer(mode(md));
    clean->reset(geo, params_);
    clean->apply(scans_, 0, 100, nullptr);
    clean->apply(scans_, 100, 200, nullptr);
    testing_support::expect_bit_identical(clean->read(all), r->read(all), geo, r->name() + " applied on after it");
  }
#endif
}

// A border beyond the grid keeps every block (CARMEN's int arithmetic would
// overflow near INT_MAX): the same map as the host's finish with a border
// that just clamps to the grid.
TEST_F(MapperCuda, FinishWithAHugeBorderKeepsTheWholeGrid) {
  for (CudaMode md : {CudaMode::Float, CudaMode::Exact}) {
    Mapper m(params_, "cuda", mode(md));
    m.insert(scans_.select(0, 100));
    const std::vector<float> grid = m.read();
    const GridGeometry &g = m.frame();
    const FinishedMap host = finish_grid(grid.data(), g.size_x, g.size_y, g.resolution, 4, g.size_x + g.size_y);
    ASSERT_EQ(host.min_x, 0);
    ASSERT_EQ(host.size_x, g.size_x / 4 - 1);
    for (int border : {g.size_x + g.size_y, 1 << 30, INT_MAX - 1, INT_MAX}) {
      const FinishedMap dev = m.finish(4, border);
      EXPECT_EQ(dev.min_x, 0) << border;
      EXPECT_EQ(dev.min_y, 0) << border;
      EXPECT_EQ(golden::digest(dev), golden::digest(host)) << m.backend_name() << " border " << border;
    }
  }
}

// nvblox's injected streams: a renderer given a stream maps on it (the same
// bytes as one with its own) and leaves it alive; before its first reset it
// has no grid to read (a State error, not a read of nothing).
TEST_F(MapperCuda, RendererOnTheCallersStreamLeavesItAlive) {
#if defined(VASCO_HAVE_CUDA)
  const GridGeometry geo = size_grid(scans_, params_);
  for (CudaMode md : {CudaMode::Float, CudaMode::Exact}) {
    cudaStream_t stream = nullptr;
    ASSERT_EQ(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking), cudaSuccess);
    std::vector<float> on_theirs, on_own;
    {
      std::unique_ptr<Renderer> theirs = make_cuda_renderer(mode(md), stream);
      expect_error(ErrorCode::State, [&] { theirs->read(GridWindow{0, 0, 1, 1}); }, "a read before any reset");
      theirs->reset(geo, params_);
      theirs->apply(scans_, 0, scans_.num_scans(), nullptr);
      on_theirs = theirs->read(GridWindow{0, 0, geo.size_x, geo.size_y});
    }
    std::unique_ptr<Renderer> own = make_cuda_renderer(mode(md));
    own->reset(geo, params_);
    own->apply(scans_, 0, scans_.num_scans(), nullptr);
    on_own = own->read(GridWindow{0, 0, geo.size_x, geo.size_y});
    testing_support::expect_bit_identical(on_own, on_theirs, geo, "the caller's stream");
    void *probe = nullptr;
    ASSERT_EQ(cudaMalloc(&probe, 64), cudaSuccess);
    EXPECT_EQ(cudaMemsetAsync(probe, 0, 64, stream), cudaSuccess) << "the renderer destroyed the caller's stream";
    EXPECT_EQ(cudaStreamSynchronize(stream), cudaSuccess);
    cudaFree(probe);
    cudaStreamDestroy(stream);
  }
#endif
}

}  // namespace
}  // namespace vasco
