// The per-thread Bresenham forms the kernels use, on a million random
// segments, on the GPU (the CPU side is in egrid_math_test.cc).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#if defined(VASCO_HAVE_CUDA)
#include "test_seed.h"
#include "line_check.h"
#include "vasco_gpu/cuda_backend.h"
#endif

namespace {

TEST(CudaBresenham, ClosedFormsMatchTheSequentialWalkOnAMillionSegments) {
#if !defined(VASCO_HAVE_CUDA)
  GTEST_SKIP() << "no usable GPU: this build has no CUDA backend";
#else
  std::string why;
  if (!vasco::cuda_usable(0, &why)) GTEST_SKIP() << "no usable GPU: " << why;
  const unsigned seed = vasco::testing_support::test_seed();
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> small(-40, 40), large(-5000, 5000), coin(0, 3);
  std::vector<int4> segs(1000000);
  for (auto &s : segs) {
    auto &d = coin(rng) == 0 ? large : small;
    s = make_int4(d(rng), d(rng), d(rng), d(rng));
  }
  std::vector<uint64_t> hashes;
  const unsigned long long bad = vasco::cuda::check_lines_on_device(segs, &hashes);
  SCOPED_TRACE("random seed " + std::to_string(seed));
  EXPECT_EQ(bad, 0u);
  size_t differ = 0;
  for (size_t i = 0; i < segs.size(); ++i)
    differ += hashes[i] != vasco::cuda::walk_hash_host(segs[i].x, segs[i].y, segs[i].z, segs[i].w);
  EXPECT_EQ(differ, 0u) << "device walks that differ from the host's";
#endif
}

}  // namespace
