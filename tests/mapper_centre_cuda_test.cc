// A fixed frame at a given centre on the GPU: exact mode's grid is CARMEN's
// egrid API's started at the centre, bit for bit; float mode's is its own
// grid of the fixed frame whose first scan stands at the centre (the same
// start pose for every scan), bit for bit.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "golden_support.h"
#include "mapper_centre_support.h"
#include "test_support.h"
#include "vasco_gpu/mapper.hpp"

namespace vasco {
namespace {

using centre_support::anchored_at_centre;
using centre_support::carmen_anchored;
using centre_support::centred_frame;
using centre_support::fr079;
using centre_support::full_resolution;
using testing_support::expect_bit_identical;

void skip_without_gpu() {
  std::string why;
  if (!golden::cuda_available(&why)) GTEST_SKIP() << "no usable GPU: " << why;
}

TEST(MapperCentreCuda, ExactModeEqualsCarmensApiAnchoredAtTheCentre) {
  skip_without_gpu();
  if (testing::Test::IsSkipped()) return;
  const GridGeometry frame = centred_frame();
  const ScanBatch scans = fr079(150, 120);  // a first scan away from the centre
  Mapper m(full_resolution(), frame, "cuda_exact");
  m.insert(scans.select(0, 50));
  m.insert(scans.select(50, 70));
  EXPECT_TRUE(m.frame().centre_given);
  EXPECT_EQ(m.frame().x0, frame.x0);
  expect_bit_identical(carmen_anchored(scans, m.params(), frame), m.read(), frame, "cuda exact");
}

TEST(MapperCentreCuda, FloatModeEqualsTheFirstScanFrameWithAScanAtTheCentre) {
  skip_without_gpu();
  if (testing::Test::IsSkipped()) return;
  const GridGeometry frame = centred_frame();
  const ScanBatch scans = fr079(150, 120);
  const auto [on_first_scan, anchored] = anchored_at_centre(frame, scans);
  Mapper centred(full_resolution(), frame, "cuda"), first_scan(full_resolution(), on_first_scan, "cuda");
  centred.insert(scans);
  first_scan.insert(anchored);
  ASSERT_EQ(first_scan.frame().x0, frame.x0);
  expect_bit_identical(first_scan.read(), centred.read(), frame, "cuda float");
}

}  // namespace
}  // namespace vasco
