// The numbers of the map_server YAML the tools write: floats to PyYAML
// (YAML 1.1) and yaml-cpp alike, and the origin's double kept exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <regex>
#include <string>

#include "carmen_compat/yaml_number.h"

namespace {

// YAML 1.1's float, as PyYAML's resolver spells it (the base-60 form left
// out): a "." is required, an exponent must be signed.
bool is_yaml11_float(const std::string &t) {
  static const std::regex kFloat(
      R"(^[-+]?([0-9][0-9_]*)?\.[0-9_]*([eE][-+][0-9]+)?$|^[-+]?\.(inf|Inf|INF)$|^\.(nan|NaN|NAN)$)");
  return std::regex_match(t, kFloat);
}

double read_back(const std::string &t) { return std::strtod(t.c_str(), nullptr); }

TEST(YamlNumber, WrittenAsPeopleWriteThem) {
  EXPECT_EQ(carmen::yaml_float_text(-100), "-100.0");
  EXPECT_EQ(carmen::yaml_float_text(10), "10.0");
  EXPECT_EQ(carmen::yaml_float_text(0.05), "0.05");
  EXPECT_EQ(carmen::yaml_float_text(1e-5), "1.0e-05");
  EXPECT_EQ(carmen::yaml_float_text(1e20), "1.0e+20");
  EXPECT_EQ(carmen::yaml_float_text(0.0), "0.0");
  EXPECT_EQ(carmen::yaml_float_text(-0.0), "-0.0");
  EXPECT_EQ(carmen::yaml_float_text(0.65), "0.65");
  EXPECT_EQ(carmen::yaml_float_text(5400000.125), "5400000.125");  // a UTM northing, not 5.4e+06
  EXPECT_EQ(carmen::yaml_float_text(0.0001), "0.0001");
  EXPECT_EQ(carmen::yaml_float_text(-2.5e-7), "-2.5e-07");
}

// 0.1 + 0.2 needs all 17 significant digits to read back as itself.
TEST(YamlNumber, ADoubleNeedingSeventeenDigitsKeepsThem) {
  const double v = 0.1 + 0.2;
  ASSERT_NE(v, 0.3);
  EXPECT_EQ(carmen::yaml_float_text(v), "0.30000000000000004");
  EXPECT_EQ(carmen::yaml_float_text(-13.499734000000002), "-13.499734000000002");
}

TEST(YamlNumber, EveryTextIsAYaml11FloatThatReadsBackExactly) {
  const double values[] = {-100,   10,     0.05,   1e-5,     1e20,   -0.0,
                           0.1 + 0.2,    1234.5678901234, -1e-300, 1.7976931348623157e308,
                           4.9e-324,     1e15,   1e16,   123456789012345678.0, 0.5, -3.5};
  for (const double v : values) {
    const std::string t = carmen::yaml_float_text(v);
    EXPECT_TRUE(is_yaml11_float(t)) << v << " -> " << t;
    EXPECT_EQ(read_back(t), v) << t;
    EXPECT_EQ(std::signbit(read_back(t)), std::signbit(v)) << t;
  }
}

TEST(YamlNumber, NotFiniteAsYamlSpellsIt) {
  EXPECT_EQ(carmen::yaml_float_text(std::numeric_limits<double>::infinity()), ".inf");
  EXPECT_EQ(carmen::yaml_float_text(-std::numeric_limits<double>::infinity()), "-.inf");
  EXPECT_EQ(carmen::yaml_float_text(std::nan("")), ".nan");
}

// The resolution is a float in a CARMEN map and in MapMetaData: the
// shortest text of that float, still a YAML float.
TEST(YamlNumber, FloatTextIsTheShortestOfTheNearestFloat) {
  EXPECT_EQ(carmen::yaml_float_text_of_float(double(0.05f)), "0.05");
  EXPECT_EQ(carmen::yaml_float_text_of_float(0.03 / 7 * 7), "0.03");
  EXPECT_EQ(carmen::yaml_float_text_of_float(10), "10.0");
  EXPECT_EQ(carmen::yaml_float_text_of_float(1e-5), "1.0e-05");
  const float f = 1234.5678901234f;
  const std::string t = carmen::yaml_float_text_of_float(1234.5678901234);
  EXPECT_EQ(t, "1234.5679");
  EXPECT_EQ(static_cast<float>(read_back(t)), f);
  EXPECT_TRUE(is_yaml11_float(t));
}

}  // namespace
