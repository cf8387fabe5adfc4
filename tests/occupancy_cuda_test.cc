// finish_kernels.cu's OccupancyGrid conversion (launch_occupancy_crop) on
// cell values a finish never makes besides those it makes: NaN, negatives,
// CARMEN's -1, 1 and values up to 2, off-limits 2 and above, +inf, the floats
// around each threshold, random probabilities; in both modes and in a crop
// that is not the whole block grid: the host's bytes
// (carmen_compat/occupancy_grid.h, checked against map_server's reading of
// our pictures in occupancy_grid_test). An empty crop writes nothing. Skips
// without a GPU.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "carmen_compat/occupancy_grid.h"
#include "golden_support.h"
#include "test_seed.h"

#if defined(VASCO_HAVE_CUDA)
#include "cuda/cuda_check.h"
#include "cuda/egrid_kernels.h"
#endif

namespace vasco {
namespace {

#if defined(VASCO_HAVE_CUDA)
// The values a cell of the finished map can hold or a test should try.
std::vector<float> cell_values(std::mt19937 &rng, size_t n, const carmen::MapServerOptions &o) {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> special = {std::nanf(""), -inf, -1.0f, -0.5f, -0.0f, 0.0f, 1e-45f, 1e-30f, 0.005f, 0.004999f,
                                0.5f, 0.995f, 1.0f, 1.5f, std::nextafter(2.0f, 0.0f), 2.0f, 3.0f, inf};
  for (const double t : {o.free_thresh, o.occupied_thresh}) {
    const float f = static_cast<float>(t);
    special.insert(special.end(), {std::nextafter(f, 0.0f), f, std::nextafter(f, 2.0f)});
  }
  std::uniform_real_distribution<float> p(0.0f, 1.0f);
  std::vector<float> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = i % 3 == 0 ? special[(i / 3) % special.size()] : p(rng);
  return v;
}

std::vector<int8_t> on_device(const std::vector<float> &blocks, finish::Blocks grid, finish::Crop crop,
                              const carmen::OccupancyValues &values) {
  cuda::DeviceBuffer<float> d_blocks(blocks.size());
  const size_t n = static_cast<size_t>(crop.count());
  cuda::DeviceBuffer<int8_t> d_out(n + 1);
  VG_CUDA_CHECK(cudaMemcpy(d_blocks.get(), blocks.data(), blocks.size() * sizeof(float), cudaMemcpyHostToDevice));
  VG_CUDA_CHECK(cudaMemset(d_out.get(), 42, n + 1));
  cuda::launch_occupancy_crop(d_blocks.get(), grid, crop, values, d_out.get(), nullptr);
  VG_CUDA_CHECK(cudaDeviceSynchronize());
  std::vector<int8_t> out(n + 1);
  VG_CUDA_CHECK(cudaMemcpy(out.data(), d_out.get(), n + 1, cudaMemcpyDeviceToHost));
  EXPECT_EQ(out[n], 42) << "a byte written past the crop";
  out.pop_back();
  return out;
}
#endif

TEST(OccupancyCuda, EveryKindOfValueIsTheHostsByte) {
  REQUIRE_GPU();
#if defined(VASCO_HAVE_CUDA)
  const unsigned seed = testing_support::test_seed();
  SCOPED_TRACE("random seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  const finish::Blocks grid{141, 97};
  const finish::Crop crop{5, 3, 131, 90};  // x-major blocks, row-major data from (5, 3)
  carmen::MapServerOptions opts[3];
  opts[1].free_thresh = 0.25;
  opts[1].occupied_thresh = 0.5;
  opts[2].mode = carmen::PgmMode::Raw;
  for (const carmen::MapServerOptions &o : opts) {
    const std::vector<float> blocks = cell_values(rng, static_cast<size_t>(grid.count()), o);
    std::vector<float> cropped;  // the crop, x-major, as the host's finish gives it
    for (int x = 0; x < crop.size_x; ++x)
      for (int y = 0; y < crop.size_y; ++y) cropped.push_back(blocks[finish::cropped_block(crop, grid, x, y)]);
    const carmen::OccupancyValues values = carmen::occupancy_values(o);
    std::vector<int8_t> want(cropped.size());
    carmen::occupancy_grid_data(cropped.data(), crop.size_x, crop.size_y, values, want.data());
    const std::vector<int8_t> got = on_device(blocks, grid, crop, values);
    ASSERT_EQ(got.size(), want.size());
    for (size_t i = 0; i < got.size(); ++i)
      ASSERT_EQ(int(got[i]), int(want[i])) << "data index " << i << ", cell value "
                                           << cropped[(i % crop.size_x) * crop.size_y + i / crop.size_x]
                                           << (values.raw ? " (raw)" : " (trinary)");
  }
  // An empty crop (CARMEN's size is max - min: one known block and no border) writes nothing.
  EXPECT_TRUE(on_device(std::vector<float>(grid.count(), 0.5f), grid, finish::Crop{7, 7, 0, 12},
                        carmen::occupancy_values(opts[0])).empty());
#endif
}

}  // namespace
}  // namespace vasco
