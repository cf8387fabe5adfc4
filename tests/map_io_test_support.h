// What the tests of CARMEN's C map API share: the user CARMEN's writers
// record, a grid in CARMEN's layout, and the fixture that runs each test on a
// plain and a gzip file (instantiate it in each test program as
// INSTANTIATE_TEST_SUITE_P(PlainAndGzip, MapIo, ...)).
#ifndef VASCO_TESTS_MAP_IO_TEST_SUPPORT_H
#define VASCO_TESTS_MAP_IO_TEST_SUPPORT_H

#include <gtest/gtest.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "map_test_support.h"

namespace mapiotest {

using maptest::chunk;
using maptest::f32;
using maptest::i32;
using maptest::kId;
using maptest::map_fixture;
using maptest::read_bytes;
using maptest::TempDir;

// What CARMEN's writers put as the user: getlogin(), or "UNKNOWN".
inline std::string login_or_unknown() {
  const char *u = getlogin();
  return u != nullptr ? u : "UNKNOWN";
}

// A size_x × size_y grid in CARMEN's layout (row pointers into one block).
struct CGrid {
  std::vector<float> block;
  std::vector<float *> rows;
  CGrid(int sx, int sy) : block(size_t(sx) * size_t(sy)), rows(size_t(sx)) {
    for (int x = 0; x < sx; ++x) rows[size_t(x)] = block.data() + size_t(x) * size_t(sy);
  }
};

class MapIo : public ::testing::TestWithParam<const char *> {
 protected:
  std::string path(const std::string &stem) const { return dir_.file(stem + GetParam()); }
  TempDir dir_;
};

// Names a MapIo test by its parameter: ".../plain" or ".../gzip".
inline std::string plain_or_gzip(const ::testing::TestParamInfo<const char *> &info) {
  return std::string(info.param).size() > 4 ? "gzip" : "plain";
}

}  // namespace mapiotest

#endif  // VASCO_TESTS_MAP_IO_TEST_SUPPORT_H
