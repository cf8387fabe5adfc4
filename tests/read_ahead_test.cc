// Batch mode's read-ahead policy (vasco_gpu/app/read_ahead.h): inputs let
// through in order, each once, within the reads under way, the inputs ahead
// of the mappers and the byte budget; the next input a mapper takes always.
#include "read_ahead.h"

#include <gtest/gtest.h>

#include <vector>

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

}  // namespace
