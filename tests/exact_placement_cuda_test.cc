// CUDA exact mode's beam placement on the device (device_placement.h) gives
// the beams the host's oracle code places (beam_placement.h) bit for bit:
// end cells, scans, ranges, used and skipped counts, for a bundled log (whole,
// and a slice whose frame scan 0 fixed), for random poses with odd ranges
// (NaN, +-inf, negative), and for beams whose end cell lies on a cell border,
// which the device leaves to the host. Its pair bound is the host's sum when
// every beam was sure, and bounds it otherwise. Past the unsure list's
// capacity it places nothing and says so; the renderer then places on the
// host and the map is cpu_double's. Skips without a GPU.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "golden_support.h"
#include "test_seed.h"
#include "test_support.h"
#include "vasco_gpu/internal/beam_placement.h"

#if defined(VASCO_HAVE_CUDA)
#include "cuda/device_placement.h"
#include "cuda/exact_pair_bound.h"
#endif

namespace vasco {
namespace {

#if defined(VASCO_HAVE_CUDA)
struct DevicePlaced {
  cuda_host::DevicePlacement::Placed result;
  std::vector<PlacedBeam> beams;
  std::vector<cuda::StartCell> starts;
};

DevicePlaced place_on_device(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
                             size_t first, size_t last) {
  cuda::Stream stream;
  cuda_host::DevicePlacement placement;
  cuda::DeviceBuffer<PlacedBeam> beams;
  cuda::DeviceBuffer<cuda::StartCell> starts;
  placement.ranges().upload(batch, last, stream.get());
  DevicePlaced out;
  out.result = placement.place(batch, first, last, geo, params, beams, starts, stream.get());
  stream.synchronize();
  out.beams.resize(out.result.beams);
  out.starts.resize(last - first);
  if (!out.beams.empty())
    VG_CUDA_CHECK(cudaMemcpy(out.beams.data(), beams.get(), out.beams.size() * sizeof(PlacedBeam),
                             cudaMemcpyDeviceToHost));
  VG_CUDA_CHECK(cudaMemcpy(out.starts.data(), starts.get(), out.starts.size() * sizeof(cuda::StartCell),
                           cudaMemcpyDeviceToHost));
  return out;
}

// Places scans [first, last) both ways and compares; returns the device's result.
cuda_host::DevicePlacement::Placed expect_placed_as_the_host(const ScanBatch &batch, const GridGeometry &geo,
                                                            const MapperParams &params, size_t first,
                                                            size_t last) {
  const PlacedBeams host = place_beams(batch, geo, params, 1, first, last);
  const DevicePlaced dev = place_on_device(batch, geo, params, first, last);
  EXPECT_TRUE(dev.result.done);
  EXPECT_EQ(dev.result.beams, host.beams.size());
  EXPECT_EQ(dev.result.skipped, host.skipped);
  if (dev.result.beams != host.beams.size()) return dev.result;
  size_t differ = 0;
  for (size_t i = 0; i < host.beams.size(); ++i) {
    const PlacedBeam &h = host.beams[i], &d = dev.beams[i];
    const bool same = h.x2 == d.x2 && h.y2 == d.y2 && h.scan == d.scan &&
                      std::memcmp(&h.range, &d.range, sizeof(float)) == 0;
    if (!same && ++differ <= 5)
      ADD_FAILURE() << "beam " << i << " of scan " << h.scan << ": host (" << h.x2 << ", " << h.y2 << "), device ("
                    << d.x2 << ", " << d.y2 << ") scan " << d.scan;
  }
  EXPECT_EQ(differ, 0u);
  for (size_t s = 0; s < host.starts.size(); ++s) {
    EXPECT_EQ(dev.starts[s].x1, host.starts[s].x1);
    EXPECT_EQ(dev.starts[s].y1, host.starts[s].y1);
  }
  const uint64_t host_bound =
      cuda_host::exact_pair_bound(host.beams.data(), host.beams.size(), host.starts, params.table_size());
  if (dev.result.unsure == 0)
    EXPECT_EQ(dev.result.pair_bound, host_bound);
  else
    EXPECT_GE(dev.result.pair_bound, host_bound);
  return dev.result;
}
#endif

TEST(ExactPlacement, ABundledLogIsPlacedAsTheHostPlacesIt) {
  REQUIRE_GPU();
#if defined(VASCO_HAVE_CUDA)
  MapperParams params;
  const auto log = testing_support::load_log(testing_support::bundled_log("intel.gfs.log.gz"), params);
  const size_t n = log.batch.num_scans();
  ASSERT_GT(n, 600u);
  expect_placed_as_the_host(log.batch, log.geo, params, 0, n);
  // A slice: scan 0 still fixes the frame.
  expect_placed_as_the_host(log.batch, log.geo, params, 250, 600);
#endif
}

TEST(ExactPlacement, RandomPosesWithOddRangesArePlacedAsTheHostPlacesThem) {
  REQUIRE_GPU();
#if defined(VASCO_HAVE_CUDA)
  const unsigned seed = testing_support::test_seed();
  SCOPED_TRACE("random seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  MapperParams params;
  params.resolution = 0.05;
  const ScanBatch batch = testing_support::random_batch(rng, 200, 9);
  const GridGeometry geo = size_grid(batch, params);
  expect_placed_as_the_host(batch, geo, params, 0, batch.num_scans());
#endif
}

// Every beam at angle 0 from a start on a cell border (the first pose is the
// frame's centre, an integer cell coordinate when the side is even): the end
// cell's y is exactly an integer, which the device cannot decide.
ScanBatch beams_on_cell_borders(int scans, int beams) {
  ScanBatch batch;
  std::vector<float> r(static_cast<size_t>(beams));
  for (int b = 0; b < beams; ++b) r[static_cast<size_t>(b)] = 0.5f + 0.25f * static_cast<float>(b % 40);
  for (int s = 0; s < scans; ++s) batch.add_scan(0, 0, 0, 0, 0, r.data(), beams, s + 1);
  return batch;
}

// The batch's grid, one cell taller where its side is odd: the first pose
// then starts on a cell border.
GridGeometry even_grid(const ScanBatch &batch, const MapperParams &params) {
  GridGeometry geo = size_grid(batch, params);
  geo.size_y += geo.size_y % 2;
  return geo;
}

TEST(ExactPlacement, BeamsEndingOnACellBorderArePlacedByTheHost) {
  REQUIRE_GPU();
#if defined(VASCO_HAVE_CUDA)
  MapperParams params;
  const ScanBatch batch = beams_on_cell_borders(3, 50);
  const GridGeometry geo = even_grid(batch, params);
  const auto placed = expect_placed_as_the_host(batch, geo, params, 0, batch.num_scans());
  EXPECT_EQ(placed.unsure, 150u);
#endif
}

TEST(ExactPlacement, TooManyUnsureBeamsPlaceNothingAndTheRendererPlacesThemOnTheHost) {
  REQUIRE_GPU();
#if defined(VASCO_HAVE_CUDA)
  MapperParams params;
  const ScanBatch batch = beams_on_cell_borders(100, 200);  // 20000 unsure beams, past the list's 16384
  const GridGeometry geo = even_grid(batch, params);
  const DevicePlaced dev = place_on_device(batch, geo, params, 0, batch.num_scans());
  EXPECT_FALSE(dev.result.done);
  EXPECT_EQ(dev.result.unsure, 20000u);
  BackendOptions o;
  o.cuda_mode = CudaMode::Exact;
  auto cuda = make_renderer("cuda", o);
  auto cpu = make_renderer("cpu_double");
  MapStats st_cuda, st_cpu;
  const std::vector<float> a = render_grid(*cuda, batch, params, geo, &st_cuda);
  const std::vector<float> b = render_grid(*cpu, batch, params, geo, &st_cpu);
  testing_support::expect_bit_identical(b, a, geo, "cuda exact");
  EXPECT_EQ(st_cuda.cell_updates, st_cpu.cell_updates);
  EXPECT_EQ(st_cuda.beams_used, st_cpu.beams_used);
#endif
}

}  // namespace
}  // namespace vasco
