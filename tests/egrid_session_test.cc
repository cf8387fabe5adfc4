// CARMEN's egrid.h on a mapping session of another backend
// (vasco_egrid_set_backend, VASCO_GPU_BACKEND): g->prob holds CARMEN's bytes
// after every call, through clears and per-beam-angle updates too.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>

#include "carmen/egrid.h"
#include "test_seed.h"
#include "test_support.h"

namespace vasco {
namespace {

class EgridSession : public ::testing::Test {
 protected:
  void TearDown() override {
    vasco_egrid_set_backend("");
    unsetenv("VASCO_GPU_BACKEND");
  }
};

// Runs the same sequence of calls on two grids and compares them, cell by
// cell, after every call.
struct Twin {
  evidence_grid a, b;  // a: the oracle; b: the backend under test
  Twin(const char *backend, int sx, int sy) {
    vasco_egrid_set_backend("cpu_double");
    init(&a, sx, sy);
    vasco_egrid_set_backend(backend != nullptr ? backend : "");
    init(&b, sx, sy);
  }
  ~Twin() {
    carmen_mapper_free_evidence_grid(&a);
    carmen_mapper_free_evidence_grid(&b);
  }
  static void init(evidence_grid *g, int sx, int sy) {
    carmen_mapper_initialize_evidence_grid(g, sx, sy, 0.05, 0.2, 0.4, 0.8, 0.35, 0.99, 2.0, 5.0, 0.1);
  }
  void expect_equal(const std::string &when) {
    ASSERT_EQ(a.size_x, b.size_x) << when;
    ASSERT_EQ(a.size_y, b.size_y) << when;
    for (int x = 0; x < a.size_x; ++x)
      if (std::memcmp(a.prob[x], b.prob[x], sizeof(float) * a.size_y) != 0) {
        for (int y = 0; y < a.size_y; ++y)
          ASSERT_EQ(a.prob[x][y], b.prob[x][y]) << when << ": cell (" << x << ", " << y << ")";
      }
    EXPECT_EQ(a.first, b.first) << when;
    EXPECT_EQ(a.start_x, b.start_x) << when;
  }
};

void random_scan(std::mt19937 &rng, std::vector<float> *r, double *x, double *y, double *t) {
  std::uniform_real_distribution<double> pos(-3, 3), ang(-M_PI, M_PI), range(0.1, 7);
  *x = pos(rng);
  *y = pos(rng);
  *t = ang(rng);
  r->resize(181);
  for (size_t i = 0; i < r->size(); ++i) (*r)[i] = i % 37 == 5 ? -INFINITY : static_cast<float>(range(rng));
}

TEST_F(EgridSession, CpuThreadsKeepsCarmensBytesThroughClearAndGeneralUpdates) {
  Twin t("cpu_threads", 260, 220);
  std::mt19937 rng(testing_support::test_seed(5));
  std::vector<float> r;
  double x, y, th;
  auto both_update = [&](const char *what) {
    random_scan(rng, &r, &x, &y, &th);
    carmen_mapper_update_evidence_grid(&t.a, x, y, th, 181, r.data(), M_PI / 180, -M_PI / 2);
    carmen_mapper_update_evidence_grid(&t.b, x, y, th, 181, r.data(), M_PI / 180, -M_PI / 2);
    t.expect_equal(what);
  };
  EXPECT_STREQ(vasco_egrid_grid_backend(&t.a), "cpu_double");
  EXPECT_STREQ(vasco_egrid_grid_backend(&t.b), "cpu_threads");
  for (int i = 0; i < 15; ++i) both_update("update");
  carmen_mapper_clear_evidence_grid(&t.a);
  carmen_mapper_clear_evidence_grid(&t.b);
  t.expect_equal("clear");
  EXPECT_STREQ(vasco_egrid_grid_backend(&t.b), "cpu_threads");
  for (int i = 0; i < 15; ++i) both_update("update after clear");
  std::vector<float> angles(181);
  for (size_t i = 0; i < angles.size(); ++i) angles[i] = static_cast<float>(-M_PI / 2 + i * M_PI / 180);
  random_scan(rng, &r, &x, &y, &th);
  carmen_mapper_update_evidence_grid_general(&t.a, x, y, th, 181, r.data(), angles.data(), 0, 0);
  carmen_mapper_update_evidence_grid_general(&t.b, x, y, th, 181, r.data(), angles.data(), 0, 0);
  t.expect_equal("general update");
  EXPECT_STREQ(vasco_egrid_grid_backend(&t.b), "cpu_double");  // the oracle from now on
  for (int i = 0; i < 5; ++i) both_update("update after a general one");
  carmen_mapper_finish_evidence_grid(&t.a, 2, 5);
  carmen_mapper_finish_evidence_grid(&t.b, 2, 5);
  t.expect_equal("finish");
}

TEST_F(EgridSession, TheEnvironmentChoosesWithoutACall) {
  setenv("VASCO_GPU_BACKEND", "cpu_threads", 1);
  Twin t(nullptr, 200, 200);
  vasco_egrid_set_backend("");  // b was initialised under the environment's choice
  EXPECT_STREQ(vasco_egrid_grid_backend(&t.b), "cpu_threads");
  std::mt19937 rng(testing_support::test_seed(6));
  std::vector<float> r;
  double x, y, th;
  for (int i = 0; i < 10; ++i) {
    random_scan(rng, &r, &x, &y, &th);
    carmen_mapper_update_evidence_grid(&t.a, x, y, th, 181, r.data(), M_PI / 180, -M_PI / 2);
    carmen_mapper_update_evidence_grid(&t.b, x, y, th, 181, r.data(), M_PI / 180, -M_PI / 2);
  }
  t.expect_equal("updates");
}

TEST_F(EgridSession, UnknownBackendsAreRefused) {
  EXPECT_EQ(vasco_egrid_set_backend("gpu9000"), -1);
  EXPECT_EQ(vasco_egrid_set_backend(nullptr), -1);
  EXPECT_EQ(vasco_egrid_set_backend("cpu_threads"), 0);
  EXPECT_EQ(vasco_egrid_set_backend(""), 0);
}

}  // namespace
}  // namespace vasco
