// CARMEN's own maps on the GPU: CUDA exact mode on every golden case the
// project carries (the same test body as golden_test), and CUDA float mode
// reported against them (see float_golden_test.cc for the bounds). Skips
// with a message when no GPU is usable.
#include "float_golden_support.h"
#include "golden_support.h"

namespace vasco {
namespace {

using golden::Case;

class GoldenCuda : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    std::string why;
    if (!golden::cuda_available(&why)) GTEST_SKIP() << "no usable GPU: " << why;
  }
};

TEST_P(GoldenCuda, ExactModeMatchesCarmen) {
  golden::expect_golden(GetParam(), golden::cuda_path(CudaMode::Exact));
}

TEST_P(GoldenCuda, ExactModeMapperSessionMatchesCarmen) {
  BackendOptions exact;
  exact.cuda_mode = CudaMode::Exact;
  golden::expect_golden(GetParam(), golden::mapper_path("cuda", exact));
}

TEST_P(GoldenCuda, ExactModeSplitInBandsMatchesCarmen) {
  golden::expect_golden(GetParam(), golden::cuda_split_path());
}

TEST_P(GoldenCuda, ExactModeMapperSessionSplitInBandsMatchesCarmen) {
  golden::Path p = golden::mapper_path("cuda", golden::split_exact_options());
  golden::expect_golden(GetParam(), p);
}

TEST_P(GoldenCuda, ExactModeUnderCarmensApiMatchesCarmen) {
  golden::expect_golden(GetParam(), golden::egrid_path("cuda_exact"));
}

TEST_P(GoldenCuda, FloatModeWithinTheFloatBounds) {
  golden::expect_float_within_bounds(GetParam(), golden::cuda_path(CudaMode::Float));
}

INSTANTIATE_TEST_SUITE_P(Carried, GoldenCuda, ::testing::ValuesIn(golden::carried_cases()),
                         [](const ::testing::TestParamInfo<Case> &info) {
                           return golden::case_label(info.param);
                         });

}  // namespace
}  // namespace vasco
