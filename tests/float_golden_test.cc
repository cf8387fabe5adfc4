// cpu_float (one core, table-driven log-odds) against CARMEN's golden maps, on every
// golden case the project carries: the DESIGN §4 table, and the bounds argued
// in float_golden_support.h.
#include "float_golden_support.h"

namespace vasco {
namespace {

class FloatGoldenCpu : public ::testing::TestWithParam<golden::Case> {};

TEST_P(FloatGoldenCpu, CpuFloatWithinTheFloatBounds) {
  golden::expect_float_within_bounds(GetParam(), golden::backend_path("cpu_float", "cpu_float"));
}

INSTANTIATE_TEST_SUITE_P(Carried, FloatGoldenCpu, ::testing::ValuesIn(golden::carried_cases()),
                         [](const ::testing::TestParamInfo<golden::Case> &info) {
                           return golden::case_label(info.param);
                         });

}  // namespace
}  // namespace vasco
