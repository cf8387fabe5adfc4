// test_seed.h — the seed of a random test: printed, recorded in the test's
// XML output, and replayable. VASCO_TEST_SEED=N in the environment replays a
// run; otherwise a test with a fixed seed keeps it and the others draw one.
#ifndef VASCO_TESTS_TEST_SEED_H
#define VASCO_TESTS_TEST_SEED_H

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <random>
#include <string>

namespace vasco {
namespace testing_support {

// fixed < 0: draw a fresh seed unless VASCO_TEST_SEED is set.
inline uint32_t test_seed(int64_t fixed = -1) {
  uint32_t seed;
  const char *env = std::getenv("VASCO_TEST_SEED");
  if (env != nullptr && *env != '\0') {
    seed = static_cast<uint32_t>(std::strtoul(env, nullptr, 10));
  } else if (fixed >= 0) {
    seed = static_cast<uint32_t>(fixed);
  } else {
    seed = std::random_device{}();
  }
  std::cout << "[ random seed " << seed << ": replay with VASCO_TEST_SEED=" << seed << " ]" << std::endl;
  ::testing::Test::RecordProperty("random_seed", std::to_string(seed));
  return seed;
}

}  // namespace testing_support
}  // namespace vasco

#endif  // VASCO_TESTS_TEST_SEED_H
