// MapperParams: defaults, reading vasco_* keys, validation with locations.
#include "vasco_gpu/params.h"

#include <gtest/gtest.h>

#include <cmath>

#include "carmen_compat/error.h"
#include "carmen_compat/ini_file.h"

namespace vasco {
namespace {

MapperParams from_text(const std::string &text, std::vector<std::string> *warnings = nullptr) {
  return MapperParams::from_params(carmen::ParamFile::parse(text, "test.ini"), warnings);
}

TEST(MapperParams, DefaultsAreVascos) {
  const MapperParams p = from_text("[*]\n");
  EXPECT_EQ(p.resolution, 0.025);
  EXPECT_EQ(p.p_prior, 0.5);
  EXPECT_EQ(p.p_occ, 0.55);
  EXPECT_EQ(p.p_emp, 0.45);
  EXPECT_EQ(p.range_sure, 5.0);
  EXPECT_EQ(p.range_max, 10.0);
  EXPECT_EQ(p.wall_size, 0.2);
  EXPECT_EQ(p.downsample, 4);
  EXPECT_EQ(p.border, 20);
  EXPECT_EQ(p.table_size(), 400);
}

TEST(MapperParams, ReadsEveryKey) {
  const MapperParams p = from_text(
      "[*]\nvasco_resolution 0.05\nvasco_p_prior 0.4\nvasco_p_occ 0.9\nvasco_p_emp 0.2\n"
      "vasco_range_sure 3\nvasco_range_max 6.4\nvasco_wall_size 0.1\nvasco_downsample 2\n"
      "vasco_border 5\nvasco_first_scan 10\nvasco_num_scans 7\n");
  EXPECT_EQ(p.resolution, 0.05);
  EXPECT_EQ(p.p_prior, 0.4);
  EXPECT_EQ(p.p_occ, 0.9);
  EXPECT_EQ(p.p_emp, 0.2);
  EXPECT_EQ(p.range_sure, 3.0);
  EXPECT_EQ(p.range_max, 6.4);
  EXPECT_EQ(p.wall_size, 0.1);
  EXPECT_EQ(p.downsample, 2);
  EXPECT_EQ(p.border, 5);
  EXPECT_EQ(p.first_scan, 10);
  EXPECT_EQ(p.num_scans, 7);
  EXPECT_EQ(p.table_size(), 128);
}

void expect_error_at(const std::string &text, const std::string &where, const std::string &key) {
  try {
    from_text(text);
    FAIL() << "expected an error for " << text;
  } catch (const carmen::FileError &e) {
    EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
  }
}

TEST(MapperParams, ValidationNamesKeyAndLine) {
  expect_error_at("[*]\nvasco_p_occ 1.0\n", "test.ini:2", "vasco_p_occ");
  expect_error_at("[*]\n\nvasco_p_emp 0\n", "test.ini:3", "vasco_p_emp");
  expect_error_at("[*]\nvasco_p_prior -0.2\n", "test.ini:2", "vasco_p_prior");
  expect_error_at("[*]\nvasco_resolution 0\n", "test.ini:2", "vasco_resolution");
  expect_error_at("[*]\nvasco_range_sure 11\n", "test.ini:2", "vasco_range_sure");
  expect_error_at("[*]\nvasco_range_max -1\n", "test.ini:2", "vasco_range_max");
  expect_error_at("[*]\nvasco_downsample 0\n", "test.ini:2", "vasco_downsample");
  expect_error_at("[*]\nvasco_border -1\n", "test.ini:2", "vasco_border");
  expect_error_at("[*]\nvasco_resolution abc\n", "test.ini:2", "vasco_resolution");
}

TEST(MapperParams, RangeSureMayEqualRangeMaxOrBeZero) {
  EXPECT_NO_THROW(from_text("[*]\nvasco_range_sure 10\n"));
  EXPECT_NO_THROW(from_text("[*]\nvasco_range_sure 0\n"));
  EXPECT_NO_THROW(from_text("[*]\nvasco_border 0\nvasco_downsample 1\n"));
}

// Values whose map could not be written or read back: a range_max of 0 (no
// cell is ever updated: an empty map), resolutions whose float in the file is
// inf or 0 (our own readers refuse such maps).
TEST(MapperParams, ValuesThatMakeUnwritableMapsNameTheirKey) {
  expect_error_at("[*]\nvasco_range_sure 0\nvasco_range_max 0\n", "test.ini:3", "vasco_range_max");
  expect_error_at("[*]\nvasco_resolution 1e39\n", "test.ini:2", "vasco_resolution");
  expect_error_at("[*]\nvasco_resolution 1e-46\n", "test.ini:2", "vasco_resolution");
}

TEST(MapperParams, AbsurdTableIsRefused) {
  // range_max / resolution over 32767 cells: the distance table alone would be
  // gigabytes (and CARMEN's int i*i + j*j overflows).
  expect_error_at("[*]\nvasco_resolution 0.0001\n", "test.ini:2", "vasco_resolution");
}

TEST(MapperParams, OverridesWinAndErrorsSayCommandLine) {
  carmen::ParamFile f = carmen::ParamFile::parse("[*]\nvasco_p_occ 0.7\n", "test.ini");
  f.set_override("vasco_p_occ", "0.8");
  EXPECT_EQ(MapperParams::from_params(f, nullptr).p_occ, 0.8);
  f.set_override("vasco_p_occ", "2");
  try {
    MapperParams::from_params(f, nullptr);
    FAIL();
  } catch (const std::exception &e) {
    EXPECT_NE(std::string(e.what()).find("command line"), std::string::npos) << e.what();
  }
}

TEST(MapperParams, UnknownVascoKeysAreWarnedButCarmensOwnAreNot) {
  std::vector<std::string> w;
  from_text("[*]\nvasco_p_ocupied 0.6\nvasco_max_usable_laser_range 81.9\nvasco_local_map_resolution 0.08\n", &w);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("test.ini:2"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("vasco_p_ocupied"), std::string::npos) << w[0];
}

// The table's defaults are the struct's initializers (two places that must
// agree: MapperParams{} is read here, not the table).
TEST(ParamTable, DefaultsAreTheStructsAndEveryDefaultIsValid) {
  const MapperParams p;
  ASSERT_EQ(param_table().size(), mapper_param_keys().size());
  for (const ParamSpec &s : param_table()) {
    SCOPED_TRACE(s.key);
    EXPECT_EQ(s.get(p), s.default_value);
    EXPECT_TRUE(s.valid(s.default_value));
    EXPECT_EQ(std::string("vasco_") + s.name, s.key);
    EXPECT_EQ(find_param(s.key), &s);
    EXPECT_EQ(find_param(s.name), &s);
  }
  EXPECT_EQ(find_param("vasco_p_ocupied"), nullptr);
  EXPECT_EQ(find_param("max_prob"), nullptr);
}

TEST(ParamTable, SetWritesTheMember) {
  MapperParams p;
  find_param("p_occ")->set(p, 0.75);
  find_param("vasco_border")->set(p, 7);
  EXPECT_EQ(p.p_occ, 0.75);
  EXPECT_EQ(p.border, 7);
}

// validate() names the key in the error itself (no caller parses the message).
void expect_param_error(const MapperParams &p, const std::string &key) {
  try {
    p.validate();
    ADD_FAILURE() << "expected an error for " << key;
  } catch (const ParamError &e) {
    EXPECT_EQ(e.key(), key) << e.what();
    EXPECT_EQ(e.code(), carmen::ErrorCode::Usage);
    EXPECT_EQ(std::string(e.what()).rfind(key, 0), 0u) << e.what();
  }
}

TEST(ParamTable, ValidateThrowsAParamErrorCarryingTheKey) {
  MapperParams p;
  p.p_emp = 1.0;
  expect_param_error(p, "vasco_p_emp");
  p = MapperParams{};
  p.wall_size = NAN;
  expect_param_error(p, "vasco_wall_size");
  p = MapperParams{};
  p.range_sure = 11;
  expect_param_error(p, "vasco_range_sure");
  p = MapperParams{};
  p.resolution = 0.0001;  // 1e5 cells of range: the joint rule
  expect_param_error(p, "vasco_range_max");
  p = MapperParams{};
  p.num_scans = 0;
  expect_param_error(p, "vasco_num_scans");
  p.num_scans = -1;
  EXPECT_NO_THROW(p.validate());
  p.first_scan = -1;
  expect_param_error(p, "vasco_first_scan");
}

TEST(ParamTable, IniErrorsAreFileErrorsOfBadInputAndOverridesAreUsage) {
  try {
    from_text("[*]\nvasco_p_occ 1.5\n");
    FAIL();
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.code(), carmen::ErrorCode::BadInput);
    EXPECT_EQ(e.line(), 2);
  }
  carmen::ParamFile f = carmen::ParamFile::parse("[*]\n", "test.ini");
  f.set_override("vasco_border", "-3");
  try {
    MapperParams::from_params(f, nullptr);
    FAIL();
  } catch (const carmen::Error &e) {
    EXPECT_EQ(e.code(), carmen::ErrorCode::Usage) << e.what();
  }
}

// --resolution's rule (docs/cli.md, "Map resolution"): the expected values are worked
// out by hand from the rule, and 0.1 and 0.05 must land on CARMEN's own
// evidence cell (0.025) exactly, so that a default map stays CARMEN's bytes.
TEST(MapResolution, KeepsTheEvidenceCellWhenABlockFits) {
  MapperParams p;
  p.set_map_resolution(0.1, false);
  EXPECT_EQ(p.downsample, 4);
  EXPECT_EQ(p.resolution, 0.025);  // 0.1 / 4 is exact: dividing by 4 only shifts the exponent
  p.set_map_resolution(0.05, false);
  EXPECT_EQ(p.downsample, 2);
  EXPECT_EQ(p.resolution, 0.025);
  EXPECT_EQ(p.map_resolution(), 0.05);
  p = MapperParams{};
  p.set_map_resolution(0.03, false);  // round(1.2) = 1: the evidence cell is the map's
  EXPECT_EQ(p.downsample, 1);
  EXPECT_EQ(p.resolution, 0.03);
  p = MapperParams{};
  p.set_map_resolution(0.01, false);  // round(0.4) = 0: at least one cell a block
  EXPECT_EQ(p.downsample, 1);
  EXPECT_EQ(p.resolution, 0.01);
  p = MapperParams{};
  p.set_map_resolution(0.2, false);
  EXPECT_EQ(p.downsample, 8);
  EXPECT_EQ(p.resolution, 0.025);
}

TEST(MapResolution, AGivenDownsampleStays) {
  MapperParams p;
  p.downsample = 1;
  p.set_map_resolution(0.05, true);
  EXPECT_EQ(p.downsample, 1);
  EXPECT_EQ(p.resolution, 0.05);
  p.downsample = 3;
  p.set_map_resolution(0.05, true);
  EXPECT_EQ(p.downsample, 3);
  EXPECT_EQ(p.resolution, 0.05 / 3);
}

TEST(MapResolution, BadCellsAreRefusedAndLeaveTheParamsAsTheyWere) {
  for (double bad : {0.0, -0.1, std::nan(""), HUGE_VAL, 1e-9, 1e9}) {
    MapperParams p;
    p.range_max = 10;
    try {
      p.set_map_resolution(bad, true);
      ADD_FAILURE() << bad << " was taken";
    } catch (const ParamError &e) {
      EXPECT_EQ(e.key(), "map_resolution");
      EXPECT_NE(std::string(e.what()).find("map resolution"), std::string::npos) << e.what();
    }
    EXPECT_EQ(p.resolution, MapperParams{}.resolution);
    EXPECT_EQ(p.downsample, MapperParams{}.downsample);
  }
  // An evidence cell too fine for the distance table: the message names the keys it made.
  MapperParams p;
  p.downsample = 1000;
  try {
    p.set_map_resolution(0.1, true);
    ADD_FAILURE() << "a 0.0001 m evidence cell with range_max 10 was taken";
  } catch (const ParamError &e) {
    EXPECT_NE(std::string(e.what()).find("vasco_downsample 1000"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("32767"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vasco
