// The log parser's block-wise range path (64 bytes of a line at a time):
// long FLASER lines whose ranges have every length around the 8-byte limit,
// any number of dots, signs, exponents, runs of separators, and tokens that
// straddle blocks; every range must be strtod's value as a float, bit for
// bit, and a line with a token that is not a number must be bad, failing at
// that token's field, as a token-by-token reading of the line says.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "carmen_compat/log_reader.h"
#include "log_reader_test_support.h"
#include "test_seed.h"

namespace {

using carmen::LineKind;
using carmen::LogMessage;

// A random range token: mostly digits and dots in the shapes logs use, at
// times longer than 7 bytes, with two dots, a sign, an exponent or no digit.
std::string random_token(std::mt19937 &rng) {
  const char kDigits[] = "0123456789";
  std::string t;
  const int len = 1 + static_cast<int>(rng() % 10);
  for (int k = 0; k < len; ++k) t += kDigits[rng() % 10];
  const int dots = rng() % 10 == 0 ? 2 : rng() % 8 == 0 ? 0 : 1;
  for (int d = 0; d < dots; ++d) t[rng() % t.size()] = '.';
  switch (rng() % 40) {
    case 0: t = "-" + t; break;
    case 1: t = "+" + t; break;
    case 2: t += "e-" + std::to_string(rng() % 30); break;
    case 3: t = "."; break;
    case 4: t = "nan"; break;
    case 5: t = "inf"; break;
    case 6: t += "x"; break;
    default: break;
  }
  return t;
}

// Whether strtod reads all of t (and it is not hexadecimal, which the
// reader's from_chars does not read).
bool strtod_reads(const std::string &t) {
  char *end = nullptr;
  std::strtod(t.c_str(), &end);
  return *end == '\0' && t.find_first_of("xX") == std::string::npos;
}

TEST(LogNumberBlock, LongRangeLinesMatchStrtod) {
  std::mt19937 rng(vasco::testing_support::test_seed(11));
  LogMessage m;
  carmen::LineError err;
  int good_lines = 0, bad_lines = 0;
  for (int it = 0; it < 3000; ++it) {
    const int n = 20 + static_cast<int>(rng() % 200);
    const bool clean = rng() % 3 == 0;  // a line of plain decimals only
    std::vector<std::string> tokens;
    std::string line = "FLASER " + std::to_string(n);
    for (int i = 0; i < n; ++i) {
      std::string t = random_token(rng);
      if (clean && !strtod_reads(t)) t = "1.5";
      tokens.push_back(t);
      const int gap = rng() % 12 == 0 ? 1 + static_cast<int>(rng() % 70) : 1;  // a long run, at times
      line += std::string(static_cast<size_t>(gap), rng() % 5 == 0 ? '\t' : ' ') + t;
    }
    line += " 1 2 0.5 1 2 0.5 100.5 host 100.5";
    int first_bad = -1;
    for (int i = 0; i < n && first_bad < 0; ++i)
      if (!strtod_reads(tokens[static_cast<size_t>(i)])) first_bad = i;
    const LineKind k = carmen::parse_log_line(line.data(), line.data() + line.size(), m, &err);
    if (first_bad >= 0) {
      ASSERT_EQ(k, LineKind::BAD) << line;
      // The failure names the first bad range (the count is field 1).
      const std::string where =
          "range[" + std::to_string(first_bad) + "] (field " + std::to_string(first_bad + 2) + ")";
      EXPECT_NE(err.message.find(where), std::string::npos)
          << err.message << "\n" << line;
      ++bad_lines;
      continue;
    }
    ASSERT_EQ(k, LineKind::MESSAGE) << line << ": " << err.message;
    ASSERT_EQ(m.laser.range.size(), static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
      const float want = static_cast<float>(std::strtod(tokens[static_cast<size_t>(i)].c_str(), nullptr));
      if (std::isnan(want)) {
        ASSERT_TRUE(std::isnan(m.laser.range[static_cast<size_t>(i)])) << line;
        continue;
      }
      ASSERT_EQ(std::memcmp(&want, &m.laser.range[static_cast<size_t>(i)], 4), 0)
          << "'" << tokens[static_cast<size_t>(i)] << "' (range " << i << ") in " << line;
    }
    EXPECT_DOUBLE_EQ(m.laser.laser_pose.x, 1.0);  // the fields after the ranges are where they were
    EXPECT_DOUBLE_EQ(m.laser.timestamp, 100.5);
    ++good_lines;
  }
  EXPECT_GT(good_lines, 500);
  EXPECT_GT(bad_lines, 500);
}

// Fewer ranges than announced, the line ending inside or after a block:
// missing, not misread from the fields that follow.
TEST(LogNumberBlock, ShortCountIsMissingNotMisread) {
  LogMessage m;
  carmen::LineError err;
  for (int have = 0; have < 40; ++have) {
    std::string line = "FLASER 40";
    for (int i = 0; i < have; ++i) line += " 1.25";
    const LineKind k = carmen::parse_log_line(line.data(), line.data() + line.size(), m, &err);
    EXPECT_EQ(k, LineKind::BAD) << line;
  }
  std::string line = "FLASER 30";
  for (int i = 0; i < 30; ++i) line += " 12.25";
  line += " 1 2 0.5 1 2 0.5 100.5 host 100.5";
  ASSERT_EQ(carmen::parse_log_line(line.data(), line.data() + line.size(), m, &err), LineKind::MESSAGE)
      << err.message;
  for (float r : m.laser.range) EXPECT_EQ(r, 12.25f);
}

}  // namespace
