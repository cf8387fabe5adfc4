// log_input: parameters from the command line, the ini and the log's own
// PARAM lines, with one precedence for every key (command line > ini > log >
// defaults), the scans they select, and errors that name the log.
#include "vasco_gpu/pipeline/log_input.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "carmen_compat/error.h"
#include "map_test_support.h"

namespace vasco {
namespace {

using maptest::TempDir;

// A FLASER line with 5 beams at laser pose (x, y, 0), timestamp t.
std::string flaser(double x, double y, int t) {
  std::ostringstream s;
  s << "FLASER 5 1.00 2.00 3.00 4.00 5.00 " << x << " " << y << " 0 0 0 0 " << t << " test " << t << "\n";
  return s.str();
}

// Ten scans at x = 0, 1, ..., 9 (lines 3..12), preceded by two PARAM lines.
std::string ten_scan_log(const std::string &params) {
  std::string text = params;
  for (int i = 0; i < 10; ++i) text += flaser(i, 0, 1000 + i);
  return text;
}

std::string write(const TempDir &dir, const std::string &name, const std::string &text) {
  std::ofstream(dir.file(name)) << text;
  return dir.file(name);
}

LogInput load(const std::string &log, const std::string &ini = "",
              const std::map<std::string, std::string> &cli = {}) {
  LogInputOptions o;
  o.log = log;
  o.param_file = ini;
  o.overrides = cli;
  return load_log_input(o);
}

const char kLogParams[] =
    "PARAM vasco_first_scan 2 nohost 0\n"
    "PARAM vasco_num_scans 3 nohost 0\n"
    "PARAM vasco_p_occ 0.7 nohost 0\n";

TEST(LogInput, TheLogsOwnParamsSelectTheScans) {
  TempDir dir;
  const LogInput in = load(write(dir, "a.log", ten_scan_log(kLogParams)));
  EXPECT_EQ(in.params.first_scan, 2);
  EXPECT_EQ(in.params.num_scans, 3);
  EXPECT_DOUBLE_EQ(in.params.p_occ, 0.7);
  ASSERT_EQ(in.batch.num_scans(), 3u);
  EXPECT_EQ(in.batch.x[0], 2.0);  // scans 2, 3, 4: x = 2, 3, 4
  EXPECT_EQ(in.batch.x[2], 4.0);
  EXPECT_EQ(in.load.laser_messages, 10);
  EXPECT_EQ(in.load.scans_used, 3);
}

TEST(LogInput, IniBeatsTheLogAndTheCommandLineBeatsBoth) {
  TempDir dir;
  const std::string log = write(dir, "a.log", ten_scan_log(kLogParams));
  const std::string ini = write(dir, "c.ini", "[*]\nvasco_num_scans 5\nvasco_p_occ 0.8\n");
  const LogInput from_ini = load(log, ini);
  EXPECT_EQ(from_ini.params.first_scan, 2);  // only the log sets it
  EXPECT_EQ(from_ini.params.num_scans, 5);
  EXPECT_DOUBLE_EQ(from_ini.params.p_occ, 0.8);
  EXPECT_EQ(from_ini.batch.num_scans(), 5u);

  const LogInput from_cli = load(log, ini, {{"vasco_num_scans", "4"}, {"vasco_first_scan", "0"}, {"vasco_p_occ", "0.9"}});
  EXPECT_EQ(from_cli.params.first_scan, 0);
  EXPECT_EQ(from_cli.params.num_scans, 4);
  EXPECT_DOUBLE_EQ(from_cli.params.p_occ, 0.9);
  ASSERT_EQ(from_cli.batch.num_scans(), 4u);
  EXPECT_EQ(from_cli.batch.x[0], 0.0);
}

TEST(LogInput, ARunPastTheLastScanNamesTheLog) {
  TempDir dir;
  const std::string log = write(dir, "a.log", ten_scan_log("PARAM vasco_first_scan 10 nohost 0\n"));
  try {
    load(log);
    FAIL() << "no error";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), log);
    EXPECT_NE(std::string(e.what()).find("vasco_first_scan 10 of 10"), std::string::npos) << e.what();
  }
}

TEST(LogInput, ABadValueInTheLogNamesItsLine) {
  TempDir dir;
  const std::string log = write(dir, "a.log", ten_scan_log("PARAM vasco_p_occ 1.5 nohost 0\n"));
  try {
    load(log);
    FAIL() << "no error";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), log);
    EXPECT_EQ(e.line(), 1);
  }
}

// A side past kMaxGridSide (2^31 - 1024 cells: 53,687 km at 2.5 cm) is refused
// while the frame is sized; a grid of many cells with sides below it is the
// memory budget's to refuse (Log2Map.AGridBeyondTheMemoryBudgetIsRefusedNamingTheLog).
TEST(LogInput, PosesTooFarApartNameTheLogAndTheExtremeScans) {
  TempDir dir;
  // Line 1: the first scan; line 2: near; line 3: 10^9 m away in x; line 4: 10^6 m in y.
  const std::string log =
      write(dir, "far.log", flaser(0, 0, 1) + flaser(1, 1, 2) + flaser(1e9, 0, 3) + flaser(0, 1e6, 4));
  try {
    load(log);
    FAIL() << "no error";
  } catch (const carmen::FileError &e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), log);
    EXPECT_NE(what.find("from the scan at line 1 to line 3 in x and line 4 in y"), std::string::npos) << what;
    EXPECT_NE(what.find("too large (each side at most 2147482624 cells)"), std::string::npos) << what;
  }
  // 10^7 m: sides of 8 * 10^8 and 8 * 10^7 cells, which an int holds: sized.
  const std::string far = write(dir, "far7.log", flaser(0, 0, 1) + flaser(1e7, 0, 2) + flaser(0, 1e6, 3));
  const LogInput in = load(far);
  EXPECT_GT(in.geo.num_cells(), uint64_t(1) << 55);
}

}  // namespace
}  // namespace vasco
