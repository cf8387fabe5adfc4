// Batch mode's read-ahead policy (vasco_gpu/app/read_ahead.h): inputs let
// through in order, each once, within the reads under way, the inputs ahead
// of the mappers and the byte budget; the next input a mapper takes always.
#include "read_ahead.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "map_test_support.h"

namespace {

using Inputs = std::vector<size_t>;

TEST(ReadAhead, LetsThroughNoMoreReadsThanMayRunAtOnce) {
  cli::ReadAhead ra(100, 4, 50, 1u << 30);
  EXPECT_EQ(ra.admit(), (Inputs{0, 1, 2, 3}));
  EXPECT_EQ(ra.admit(), Inputs{});  // each once
  ra.read(0, 1000);
  ra.read(1, 1000);
  EXPECT_EQ(ra.admit(), (Inputs{4, 5}));
}

TEST(ReadAhead, ReadsAheadOfTheMappersUpToMost) {
  cli::ReadAhead ra(100, 4, 6, 1u << 30);
  std::vector<size_t> all;
  for (int round = 0; round < 5; ++round)
    for (size_t i : ra.admit()) {
      all.push_back(i);
      ra.read(i, 1000);
    }
  EXPECT_EQ(all, (Inputs{0, 1, 2, 3, 4, 5}));  // six read, none taken
  ra.taken(0);
  ra.released(0);
  EXPECT_EQ(ra.admit(), Inputs{6});
}

TEST(ReadAhead, StopsAtTheBudgetAndGoesOnWhenBytesAreReleased) {
  // 100-byte inputs, a 350-byte budget: three read and a fourth under way
  // (counted at the mean) would pass it.
  cli::ReadAhead ra(20, 8, 20, 350);
  EXPECT_EQ(ra.admit().size(), 8u);  // nothing read yet: the reads under way bound it
  for (size_t i = 0; i < 8; ++i) ra.read(i, 100);
  EXPECT_EQ(ra.held_bytes(), 800u);
  EXPECT_EQ(ra.admit(), Inputs{});  // over the budget: no more
  for (size_t i = 0; i < 6; ++i) {
    ra.taken(i);
    ra.released(i);
  }
  EXPECT_EQ(ra.held_bytes(), 200u);
  EXPECT_EQ(ra.admit(), Inputs{8});  // 200 + 100 fits, 200 + 2 x 100 does not
  ra.read(8, 100);
  EXPECT_EQ(ra.admit(), Inputs{});
}

TEST(ReadAhead, TheNextInputTakenPassesWhateverItsSize) {
  cli::ReadAhead one(5, 1, 4, 10);
  EXPECT_EQ(one.admit(), Inputs{0});
  one.read(0, 1000);  // a hundred times the budget
  EXPECT_EQ(one.admit(), Inputs{});  // input 0 is the next to be taken
  one.taken(0);
  EXPECT_EQ(one.admit(), Inputs{1});  // now input 1 is, held bytes or not
  one.released(0);
  one.read(1, 1000);
  EXPECT_EQ(one.admit(), Inputs{});
  one.taken(1);
  EXPECT_EQ(one.admit(), Inputs{2});
}

TEST(ReadAhead, FailedReadsHoldNothingAndStopEndsIt) {
  cli::ReadAhead ra(10, 2, 10, 200);
  EXPECT_EQ(ra.admit(), (Inputs{0, 1}));
  ra.read(0, 0);  // failed: holds nothing, says nothing of the sizes
  ra.read(1, 100);
  EXPECT_EQ(ra.held_bytes(), 100u);
  EXPECT_EQ(ra.admit(), Inputs{2});  // 100 + 1 x 100 fits; 100 + 2 x 100 would not
  ra.stop();
  ra.taken(2);
  EXPECT_EQ(ra.admit(), Inputs{});
}

// A batch run in steps against `ra`, each read taking `actual[i]` bytes:
// what is let through starts, the oldest read ends, a mapper takes the next
// input once it is read and releases it once mapped. Returns the most bytes
// held at once, the reads under way counted at their full size (as if each
// had read all of it at once).
uint64_t peak_bytes(cli::ReadAhead &ra, const std::vector<uint64_t> &actual) {
  std::set<size_t> reading;
  std::vector<bool> done(actual.size(), false);
  uint64_t peak = 0;
  size_t next_taken = 0;
  auto account = [&] {
    uint64_t bytes = ra.held_bytes();
    for (size_t i : reading) bytes += actual[i];
    peak = std::max(peak, bytes);
  };
  while (next_taken < actual.size()) {
    for (size_t i : ra.admit()) reading.insert(i);
    account();
    if (!reading.empty()) {
      const size_t oldest = *reading.begin();
      reading.erase(reading.begin());
      ra.read(oldest, actual[oldest]);
      done[oldest] = true;
    }
    if (done[next_taken]) {
      ra.taken(next_taken);
      for (size_t i : ra.admit()) reading.insert(i);
      account();
      ra.released(next_taken++);
    }
  }
  return peak;
}

// Six inputs that each parse to 289 MB, three pool threads (six reads at
// once), a 1 GiB budget: counted at their estimates from the start, the
// reads let through never pass the budget, where counted at the mean size
// read so far (none, at the start) all six ran at once.
TEST(ReadAhead, ReadsUnderWayCountAtTheirEstimatesBeforeAnySizeIsKnown) {
  const uint64_t mb = 1000 * 1000, budget = uint64_t{1} << 30;
  const std::vector<uint64_t> actual(6, 289 * mb);
  cli::ReadAhead blind(6, 6, 24, budget);
  EXPECT_EQ(blind.admit().size(), 6u);  // no estimates: nothing is known before the first read ends
  cli::ReadAhead counted(6, 6, 24, budget, std::vector<uint64_t>(6, 300 * mb));
  EXPECT_EQ(counted.admit(), (Inputs{0, 1, 2}));  // 4 x 300 MB would pass 1 GiB
  EXPECT_EQ(counted.reserved_bytes(), 900 * mb);
  cli::ReadAhead run(6, 6, 24, budget, std::vector<uint64_t>(6, 300 * mb));
  EXPECT_LE(peak_bytes(run, actual), budget);
  EXPECT_EQ(run.held_bytes(), 0u);
  EXPECT_EQ(run.reserved_bytes(), 0u);
}

// fr079's case: logs estimated at 76 MB (8 bytes per byte of text) that
// parse to 8 MB, 32 reads at once, 128 ahead, a 1 GiB budget. Counted at
// their estimates, 14 reads run at first and fewer the further they run
// ahead; once a read has ended, the budget counts the rest at the share of
// its estimate it came to, and only the worst case (here 16 GiB) at the
// estimate: all 32 run, until 128 are ahead.
TEST(ReadAhead, ReadsUnderWayCountAtTheShareOfTheirEstimateAReadCameTo) {
  const uint64_t mb = 1000 * 1000, budget = uint64_t{1} << 30;
  const std::vector<uint64_t> estimates(200, 76 * mb);
  cli::ReadAhead before(200, 32, 128, budget, estimates);
  EXPECT_EQ(before.admit().size(), 14u);
  before.read(0, 8 * mb);
  EXPECT_EQ(before.admit().size(), 1u);  // 8 MB held: still 14 under way
  for (size_t i = 1; i < 15; ++i) before.read(i, 8 * mb);
  EXPECT_EQ(before.admit().size(), 12u);  // 15 held, 12 under way: 1 GiB at 76 MB each

  cli::ReadAhead now(200, 32, 128, budget, estimates, 16 * budget);
  EXPECT_EQ(now.admit().size(), 14u);  // nothing read yet: counted at the estimate
  now.read(0, 8 * mb);
  EXPECT_EQ(now.admit().size(), 19u);  // 32 under way, all now counted at 8 MB
  EXPECT_EQ(now.expected_bytes(), 32 * 8 * mb);
  EXPECT_EQ(now.reserved_bytes(), 32 * 76 * mb);
  size_t admitted = 33;
  for (size_t i = 1; i < admitted; ++i) {  // every read let through ends
    now.read(i, 8 * mb);
    admitted += now.admit().size();
  }
  EXPECT_EQ(admitted, 128u);  // `most` ahead, none taken
  EXPECT_LE(now.held_bytes(), budget);
}

// Inputs that parse to far more of their estimate than the first did: the
// budget may be passed by the reads under way, the worst case never.
TEST(ReadAhead, TheWorstCaseHoldsWhateverTheInputsParseTo) {
  const uint64_t mb = 1000 * 1000, budget = 200 * mb, worst = 1000 * mb;
  std::vector<uint64_t> actual(40, 100 * mb);
  actual[0] = 1 * mb;  // the first parses to a hundredth of its estimate, the rest to all of it
  cli::ReadAhead ra(40, 16, 40, budget, std::vector<uint64_t>(40, 100 * mb), worst);
  EXPECT_LE(peak_bytes(ra, actual), worst);
  EXPECT_EQ(ra.held_bytes(), 0u);
  EXPECT_EQ(ra.reserved_bytes(), 0u);
  EXPECT_EQ(ra.expected_bytes(), 0u);
}

// A read with no estimate (a pipe) says nothing of what a file's estimate
// overstates: inputs with one stay counted at it until a read with one ends.
TEST(ReadAhead, APipesReadLeavesTheEstimatesAsTheyAre) {
  std::vector<uint64_t> estimates(10, 400);
  estimates[0] = 0;  // input 0 is a pipe
  cli::ReadAhead ra(10, 8, 10, 1000, estimates, 100000);
  EXPECT_EQ(ra.admit(), (Inputs{0, 1, 2}));  // 0 + 400 + 400; a third 400 would pass 1000
  ra.read(0, 10);
  EXPECT_EQ(ra.admit(), Inputs{});  // still 800 expected of inputs 1 and 2, 400 more would pass
  ra.read(1, 40);                   // a tenth of its estimate: the rest counted so
  EXPECT_EQ(ra.expected_bytes(), 40u);
  EXPECT_EQ(ra.admit(), (Inputs{3, 4, 5, 6, 7, 8, 9}));
}

// The mean read so far counts where it is more than an input's estimate.
TEST(ReadAhead, AReadUnderWayCountsAtTheMeanWhereThatIsMore) {
  cli::ReadAhead ra(10, 2, 10, 1000, std::vector<uint64_t>(10, 10));
  EXPECT_EQ(ra.admit(), (Inputs{0, 1}));
  EXPECT_EQ(ra.reserved_bytes(), 20u);
  ra.read(0, 400);
  ra.read(1, 400);
  EXPECT_EQ(ra.reserved_bytes(), 0u);
  EXPECT_EQ(ra.admit(), Inputs{});  // 800 + 400 does not fit (at its estimate, 800 + 10 would)
  ra.taken(0);
  ra.released(0);
  EXPECT_EQ(ra.admit(), (Inputs{2}));  // 400 + 400 fits
  EXPECT_EQ(ra.reserved_bytes(), 400u);
}

// An estimate larger than the budget: only the next input taken runs.
TEST(ReadAhead, AnEstimateOverTheBudgetRunsOnlyOneAhead) {
  cli::ReadAhead ra(3, 4, 4, 100, std::vector<uint64_t>(3, UINT64_MAX));
  EXPECT_EQ(ra.admit(), Inputs{0});
  ra.read(0, 50);
  EXPECT_EQ(ra.admit(), Inputs{});
  ra.taken(0);
  EXPECT_EQ(ra.admit(), Inputs{1});
}

// The estimate from a file: its text's size (a gzip file's from its
// trailer) times kParsedPerTextByte, at most the cap.
TEST(ReadAheadEstimate, FromAPlainOrAGzipFilesTextSize) {
  maptest::TempDir dir;
  const std::string text(100000, '0');
  maptest::write_bytes(dir.file("a.log"), text);
  maptest::gzip_to_file(dir.file("a.log.gz"), text);
  ASSERT_LT(maptest::read_bytes(dir.file("a.log.gz")).size(), 1000u);  // what made the read-ahead blind
  EXPECT_EQ(cli::parsed_bytes_estimate(dir.file("a.log"), 0), 100000 * cli::kParsedPerTextByte);
  EXPECT_EQ(cli::parsed_bytes_estimate(dir.file("a.log.gz"), 0), 100000 * cli::kParsedPerTextByte);
  EXPECT_EQ(cli::parsed_bytes_estimate(dir.file("a.log.gz"), 12345), 12345u);
  EXPECT_EQ(cli::parsed_bytes_estimate(dir.file("none.log"), 0), 0u);
}

// A gzip file far larger than its trailer's size (several members, or 4 GiB
// of text or more): the largest text deflate could make of it.
TEST(ReadAheadEstimate, AGzipTrailerThatCannotBeTheTextsSize) {
  maptest::TempDir dir;
  maptest::gzip_to_file(dir.file("one.gz"), std::string(100000, '0'));
  const std::string member = maptest::read_bytes(dir.file("one.gz"));
  std::string many;
  for (int i = 0; i < 100; ++i) many += member;
  maptest::gzip_to_file(dir.file("tiny.gz"), "0");
  many += maptest::read_bytes(dir.file("tiny.gz"));  // the trailer says 1 byte
  maptest::write_bytes(dir.file("many.gz"), many);
  EXPECT_EQ(cli::parsed_bytes_estimate(dir.file("many.gz"), 0),
            many.size() * cli::kMaxDeflateRatio * cli::kParsedPerTextByte);
}

}  // namespace
