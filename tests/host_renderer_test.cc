// The CPU backends' grid (host_renderer.cc) after a reset: a grid of the
// same shape is reset lazily, and cpu_float renders a reset grid in its own
// cells, so the cells an earlier render wrote and the next one does not
// reach must still read unknown. Each check is against a fresh renderer's
// grid, bit for bit, on every CPU backend.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "test_seed.h"
#include "test_support.h"
#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/renderer.h"

namespace vasco {
namespace {

const char *const kHostBackends[] = {"cpu_double", "cpu_threads", "cpu_float"};

// The corners (test_support.h), each rendered alone on a fresh renderer.
struct Corners : testing_support::CornerClusters {
  explicit Corners(unsigned seed) : CornerClusters(seed, 8) {}

  std::vector<float> fresh(const std::string &backend, const ScanBatch &scans) const {
    return fresh(backend, scans, geo);
  }
  std::vector<float> fresh(const std::string &backend, const ScanBatch &scans, const GridGeometry &g) const {
    return render_grid(*make_renderer(backend), scans, params, g);
  }
};

std::string where(const std::vector<float> &want, const std::vector<float> &got) {
  const size_t i = testing_support::first_difference(want, got);
  if (i == want.size()) return "";
  return "cell " + std::to_string(i) + ": fresh " + std::to_string(want[i]) + ", reused " + std::to_string(got[i]);
}

size_t known_cells(const std::vector<float> &cells) {
  size_t n = 0;
  for (float v : cells) n += v != egrid::kUnknown;
  return n;
}

TEST(HostGridRenderer, ARenderElsewhereAfterAResetHoldsOnlyItsOwnCells) {
  const Corners c(testing_support::test_seed());
  for (const char *backend : kHostBackends) {
    SCOPED_TRACE(backend);
    const std::unique_ptr<Renderer> reused = make_renderer(backend);
    ASSERT_GT(known_cells(render_grid(*reused, c.drive, c.params, c.geo)), 100000u) << "the drive spans the grid";
    const std::vector<float> want_a = c.fresh(backend, c.a), want_b = c.fresh(backend, c.b);
    ASSERT_GT(known_cells(want_a), 1000u);
    EXPECT_EQ(where(want_a, render_grid(*reused, c.a, c.params, c.geo)), "") << "a corner after the drive";
    EXPECT_EQ(where(want_b, render_grid(*reused, c.b, c.params, c.geo)), "") << "the other corner after the first";
    reused->reset(c.geo, c.params);
    EXPECT_EQ(known_cells(reused->read(GridWindow{0, 0, c.geo.size_x, c.geo.size_y})), 0u) << "read after a reset";
    EXPECT_EQ(known_cells(reused->finish(1, 0).cells), 0u) << "finish after a reset";
    EXPECT_EQ(where(want_a, render_grid(*reused, c.a, c.params, c.geo)), "") << "after a reset read back";
    EXPECT_EQ(known_cells(render_grid(*reused, ScanBatch(), c.params, c.geo)), 0u) << "no scans after a render";
    reused->reset(c.geo, c.params);
    reused->reset(c.geo, c.params);
    EXPECT_EQ(where(want_b, render_grid(*reused, c.b, c.params, c.geo)), "") << "after two resets";
  }
}

// A grid updated in two calls (the second from a later scan: no reset
// before it) and then reset: the next render still starts from unknown
// cells everywhere the second call wrote.
TEST(HostGridRenderer, ARenderAfterAnIncrementalCallHoldsOnlyItsOwnCells) {
  const Corners c(testing_support::test_seed() + 1);
  for (const char *backend : kHostBackends) {
    SCOPED_TRACE(backend);
    const size_t half = c.drive.num_scans() / 2;
    const auto split = [&](Renderer &r) {
      r.reset(c.geo, c.params);
      r.apply(c.drive, 0, half, nullptr);
      r.apply(c.drive, half, c.drive.num_scans(), nullptr);
      return r.read(GridWindow{0, 0, c.geo.size_x, c.geo.size_y});
    };
    const std::unique_ptr<Renderer> reused = make_renderer(backend);
    render_grid(*reused, c.b, c.params, c.geo);
    EXPECT_EQ(where(split(*make_renderer(backend)), split(*reused)), "") << "the drive in two calls";
    EXPECT_EQ(where(c.fresh(backend, c.a), render_grid(*reused, c.a, c.params, c.geo)), "") << "then a corner";
  }
}

// The grid's shape changes between renders (a Mapper's frame follows its
// poses): smaller, then wider than tall, then the first again, taller (into
// the buffer's room) and twice as wide (past it). The buffer is kept at its
// largest, and cells one shape wrote lie elsewhere in the next.
TEST(HostGridRenderer, GridsOfOtherShapesAfterAResetHoldOnlyTheirOwnCells) {
  const Corners c(testing_support::test_seed() + 2);
  GridGeometry small = c.geo, wide = c.geo;
  small.size_x = c.geo.size_x * 2 / 3, small.size_y = c.geo.size_y * 3 / 5;
  wide.size_x = c.geo.size_x + c.geo.size_x / 3, wide.size_y = c.geo.size_y / 2;
  for (const char *backend : kHostBackends) {
    SCOPED_TRACE(backend);
    const std::unique_ptr<Renderer> reused = make_renderer(backend);
    render_grid(*reused, c.drive, c.params, c.geo);
    const std::vector<float> small_a = c.fresh(backend, c.a, small), wide_d = c.fresh(backend, c.drive, wide);
    ASSERT_GT(known_cells(small_a), 1000u);
    ASSERT_GT(known_cells(wide_d), 1000u);
    EXPECT_EQ(where(small_a, render_grid(*reused, c.a, c.params, small)), "") << "smaller";
    EXPECT_EQ(where(wide_d, render_grid(*reused, c.drive, c.params, wide)), "") << "wider";
    EXPECT_EQ(where(c.fresh(backend, c.drive), render_grid(*reused, c.drive, c.params, c.geo)), "") << "the first";
    EXPECT_EQ(where(small_a, render_grid(*reused, c.a, c.params, small)), "") << "smaller again";
    EXPECT_EQ(where(c.fresh(backend, c.a), render_grid(*reused, c.a, c.params, c.geo)), "") << "the first again";
    GridGeometry taller = c.geo, larger = c.geo;  // into the buffer's room, then past it
    taller.size_y += c.geo.size_y / 16;
    larger.size_x *= 2;
    EXPECT_EQ(where(c.fresh(backend, c.drive, taller), render_grid(*reused, c.drive, c.params, taller)), "") << "taller";
    EXPECT_EQ(where(c.fresh(backend, c.a, larger), render_grid(*reused, c.a, c.params, larger)), "") << "larger";
  }
}

}  // namespace
}  // namespace vasco
