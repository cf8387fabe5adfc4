// vasco::Mapper, the mapping session: incremental inserts equal one-shot
// maps, a render with new poses equals a fresh map of a log carrying them,
// growth, a fixed frame equals CARMEN's own API, and errors leave the
// session as it was. Exact backends are compared bit for bit.
#include "vasco_gpu/mapper.hpp"

#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>

#include "carmen/egrid.h"
#include "golden_support.h"
#include "map_test_support.h"
#include "test_seed.h"
#include "test_support.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/internal/log_odds.h"
#include "vasco_gpu/internal/oracle.h"
#include "vasco_gpu/internal/sensor_params.h"

namespace vasco {
namespace {

using testing_support::bundled_log;

// fr079 at full resolution (downsample 1), its first `n` scans.
struct Fixture {
  MapperParams params;
  ScanBatch scans;
};

Fixture fr079(size_t n) {
  Fixture f;
  f.params.downsample = 1;
  LogLoadStats st;
  f.scans = load_scans(bundled_log("fr079-complete.gfs.log.gz"), f.params, carmen::LogReaderOptions{}, &st)
                .select(0, static_cast<long>(n));
  return f;
}

// Scans [a, b) of a batch.
ScanBatch part(const ScanBatch &s, size_t a, size_t b) { return s.select(static_cast<long>(a), static_cast<long>(b - a)); }

struct ExactCase {
  const char *name;
  const char *backend;
  int threads;
};

class MapperExact : public ::testing::TestWithParam<ExactCase> {
 protected:
  Mapper make(const MapperParams &p) {
    BackendOptions o;
    o.threads = GetParam().threads;
    return Mapper(p, GetParam().backend, o);
  }
};

TEST_P(MapperExact, InsertsInPiecesEqualOneShot) {
  const Fixture f = fr079(400);
  std::mt19937 rng(testing_support::test_seed(9));
  std::uniform_int_distribution<int> piece(1, 40);
  Mapper m = make(f.params);
  for (size_t a = 0; a < f.scans.num_scans();) {
    const size_t b = std::min(f.scans.num_scans(), a + piece(rng));
    m.insert(part(f.scans, a, b));
    a = b;
  }
  // frame() is the PROTOCOL frame of every scan (the renderer's grid has a
  // margin after growth, unseen), and its grid and finish are one call's.
  const GridGeometry protocol = size_grid(f.scans, f.params);
  ASSERT_EQ(m.frame().size_x, protocol.size_x);
  ASSERT_EQ(m.frame().size_y, protocol.size_y);
  EXPECT_GT(m.renders(), 1u) << "fr079's first scans should grow the frame";
  const auto one_shot = render_grid(*make_renderer("cpu_double"), f.scans, f.params, protocol, nullptr);
  testing_support::expect_bit_identical(one_shot, m.read(), protocol, m.backend_name());
  const FinishedMap fin = finish_grid(one_shot.data(), protocol.size_x, protocol.size_y, protocol.resolution, 4, 20);
  EXPECT_EQ(golden::digest(m.finish(4, 20)), golden::digest(fin));
  // In the PROTOCOL frame without a margin: what render(poses()) does.
  m.render(m.poses());
  testing_support::expect_bit_identical(one_shot, m.read(), protocol, m.backend_name() + ", rendered again");
}

// start_over: a second log mapped on the same renderer gives the map a
// fresh Mapper gives it (nothing of the first log stays), new params in
// force; refused params change nothing.
TEST_P(MapperExact, StartOverMapsTheNextLogAsAFreshMapper) {
  const Fixture f = fr079(400);
  const ScanBatch first = part(f.scans, 0, 200), second = part(f.scans, 200, 400);
  MapperParams other = f.params;
  other.p_occ = 0.7;  // the second log's own parameters
  Mapper m = make(f.params);
  m.insert(first);
  MapperParams bad = other;
  bad.resolution = -1;
  EXPECT_THROW(m.start_over(bad), Error);
  EXPECT_EQ(m.num_scans(), first.num_scans()) << "a refused start_over changes nothing";
  m.start_over(other);
  EXPECT_EQ(m.num_scans(), 0u);
  EXPECT_EQ(m.params().p_occ, 0.7);
  m.insert(second);
  Mapper fresh = make(other);
  fresh.insert(second);
  testing_support::expect_bit_identical(fresh.read(), m.read(), fresh.frame(), m.backend_name() + " after start_over");
  EXPECT_EQ(golden::digest(m.finish()), golden::digest(fresh.finish()));
}

TEST_P(MapperExact, RenderWithNewPosesEqualsAFreshMapOfALogCarryingThem) {
  const Fixture f = fr079(600);
  Mapper m = make(f.params);
  m.insert(f.scans);
  // A loop-closure correction: the second half of the trajectory rotated by
  // 2 degrees about the pose of scan 300.
  std::vector<Pose> poses = m.poses();
  const Pose pivot = poses[300];
  const double a = 2.0 * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
  for (size_t i = 300; i < poses.size(); ++i) {
    const double dx = poses[i].x - pivot.x, dy = poses[i].y - pivot.y;
    poses[i] = {pivot.x + c * dx - s * dy, pivot.y + s * dx + c * dy, poses[i].theta + a};
  }
  m.render(poses);

  // The same poses written into a CARMEN log (17 significant digits round-trip
  // a double, 9 a float), read back as log2map reads a log, mapped afresh.
  maptest::TempDir dir;
  const std::string log = dir.file("moved.log");
  {
    std::FILE *out = std::fopen(log.c_str(), "w");
    ASSERT_NE(out, nullptr);
    for (size_t i = 0; i < poses.size(); ++i) {
      std::fprintf(out, "FLASER %d", m.scans().beams_in(i));
      for (int b = 0; b < m.scans().beams_in(i); ++b) std::fprintf(out, " %.9g", m.scans().ranges_of(i)[b]);
      std::fprintf(out, " %.17g %.17g %.17g 0 0 0 %zu test 0\n", poses[i].x, poses[i].y, poses[i].theta, i);
    }
    std::fclose(out);
  }
  LogInputOptions in_opt;
  in_opt.log = log;
  in_opt.overrides = {{"vasco_downsample", "1"}};
  const LogInput in = load_log_input(in_opt);
  ASSERT_EQ(in.geo.size_x, m.frame().size_x);
  ASSERT_EQ(in.geo.size_y, m.frame().size_y);
  const FinishedMap fresh = golden::finish(render_grid(*make_renderer("cpu_double"), in.batch, in.params, in.geo), in);
  EXPECT_EQ(golden::digest(m.finish()), golden::digest(fresh));
}

TEST_P(MapperExact, FixedFrameEqualsCarmensApiCallByCall) {
  const Fixture f = fr079(200);
  GridGeometry frame;
  frame.size_x = 900;  // smaller than the PROTOCOL frame: cells outside are skipped, as in CARMEN
  frame.size_y = 700;
  frame.resolution = f.params.resolution;
  frame.theta_offset = 0.3;
  Mapper m(f.params, frame, GetParam().backend);
  evidence_grid g;
  const MapperParams &p = f.params;
  carmen_mapper_initialize_evidence_grid(&g, frame.size_x, frame.size_y, p.resolution, frame.theta_offset,
                                         p.p_prior, p.p_occ, p.p_emp, 0.99, p.range_sure, p.range_max,
                                         p.wall_size);
  for (size_t s = 0; s < f.scans.num_scans(); ++s) {
    m.insert(part(f.scans, s, s + 1));
    std::vector<float> r(f.scans.ranges_of(s), f.scans.ranges_of(s) + f.scans.beams_in(s));
    carmen_mapper_update_evidence_grid(&g, f.scans.x[s], f.scans.y[s], f.scans.theta[s], f.scans.beams_in(s),
                                       r.data(), f.scans.angle_step[s], f.scans.first_angle[s]);
  }
  EXPECT_EQ(m.renders(), 1u);  // a fixed frame never grows
  std::vector<float> carmen(static_cast<size_t>(frame.size_x) * frame.size_y);
  for (int x = 0; x < frame.size_x; ++x)
    for (int y = 0; y < frame.size_y; ++y) carmen[static_cast<size_t>(x) * frame.size_y + y] = g.prob[x][y];
  carmen_mapper_free_evidence_grid(&g);
  testing_support::expect_bit_identical(carmen, m.read(), m.frame(), m.backend_name());
}

INSTANTIATE_TEST_SUITE_P(Backends, MapperExact,
                         ::testing::Values(ExactCase{"cpu_double", "cpu_double", 0},
                                           ExactCase{"cpu_threads_3", "cpu_threads", 3}),
                         [](const ::testing::TestParamInfo<ExactCase> &i) { return std::string(i.param.name); });

// How many updates each cell of `geo` gets from `batch`: the oracle's
// placement and walk (oracle.h), counted instead of applied — a route apart
// from cpu_float's closed-form walk.
std::vector<uint32_t> oracle_update_counts(const ScanBatch &batch, const MapperParams &params,
                                           const GridGeometry &geo) {
  oracle::GridFrame frame;
  frame.size_x = geo.size_x;
  frame.size_y = geo.size_y;
  frame.resolution = geo.resolution;
  frame.theta_offset = geo.theta_offset;
  const auto model = sensor_model_of(params);
  const int table = params.table_size();
  std::vector<uint32_t> counts(geo.num_cells(), 0);
  for (size_t s = 0; s < batch.num_scans(); ++s) {
    const oracle::ScanStart start = oracle::scan_start(frame, batch.x[s], batch.y[s], batch.theta[s]);
    oracle::SteppedAngles angle_of{batch.first_angle[s], batch.angle_step[s]};
    const float *ranges = batch.ranges_of(s);
    double angle = 0;
    for (int b = 0; b < batch.beams_in(s); ++b) {
      angle_of(b, start.theta, &angle);
      if (!oracle::beam_used(ranges[b])) continue;
      int x2, y2;
      oracle::beam_end(start, angle, ranges[b], params.wall_size, geo.resolution, &x2, &y2);
      egrid::walk_beam_cells(start.x1, start.y1, x2, y2, table, geo.size_x, geo.size_y,
                             [&](int cx, int cy, int i, int j) {
                               double p;
                               const double d = oracle::table_distance(i, j, table, nullptr, geo.resolution);
                               if (!egrid::sensor_model(model, d, static_cast<double>(ranges[b]), &p)) return false;
                               ++counts[egrid::cell_index(cx, cy, geo.size_y)];
                               return true;
                             });
    }
  }
  return counts;
}

TEST(MapperSession, CpuFloatInsertsAreRepeatableAndNearItsOneShot) {
  // cpu_float sums a call's updates in float log-odds and turns each touched
  // cell back into a float probability once per call: a session of 22
  // inserts rounds a cell 22 times where one call rounds it once. So: the
  // same bytes for the same inserts, the same cells known as in one call,
  // and values within the rounding, bounded cell by cell:
  //  - a float probability p carries a log-odds error of at most
  //    ulp(p) / (2 p (1 - p)); for p in [0.01, 0.99] that is
  //    2^-25 / 0.0099 < 3.1e-6 per rounding, 21 roundings more than in one
  //    call: < 6.6e-5;
  //  - a float sum of n increments, each at most t in size, is off by at most
  //    (n - 1) u n t (u = 2^-24; the standard bound on recursive summation,
  //    |S| <= n t); the one call sums the cell's n updates, the session each
  //    insert's n_k (sum of n_k^2 <= n^2), so the two differ by at most
  //    2 (n - 1) u n t, with n counted by the oracle's walk;
  //  - then |dp| <= |dL| / 4 plus two final roundings (2^-24).
  // A cell that left [0.01, 0.99] after some insert is outside the bound:
  // near 0 and 1 a float holds few log-odds bits, and at exactly 0 or 1 it
  // is pinned for good.
  const Fixture f = fr079(150);
  // A fixed frame: a growing one would re-render everything in one call.
  const GridGeometry frame = size_grid(f.scans, f.params);
  std::vector<bool> left_range(frame.num_cells(), false);
  auto session = [&] {
    Mapper m(f.params, frame, "cpu_float", BackendOptions{});
    for (size_t a = 0; a < f.scans.num_scans(); a += 7) {
      m.insert(part(f.scans, a, std::min(a + 7, f.scans.num_scans())));
      const std::vector<float> now = m.read();
      for (size_t c = 0; c < now.size(); ++c)
        if (now[c] != egrid::kUnknown && (now[c] < 0.01f || now[c] > 0.99f)) left_range[c] = true;
    }
    return m.read();
  };
  const std::vector<float> inserted = session();
  testing_support::expect_bit_identical(inserted, session(), frame, "cpu_float, the same inserts again");
  const auto one_shot = render_grid(*make_renderer("cpu_float"), f.scans, f.params, frame);
  ASSERT_EQ(one_shot.size(), inserted.size());
  const std::vector<uint32_t> updates = oracle_update_counts(f.scans, f.params, frame);
  const double t = std::max(std::fabs(logit(f.params.p_occ) - logit(f.params.p_prior)),
                            std::fabs(logit(f.params.p_emp) - logit(f.params.p_prior)));
  const double u = std::ldexp(1.0, -24);
  size_t known = 0, compared = 0, beyond = 0, tight = 0;
  for (size_t c = 0; c < one_shot.size(); ++c) {
    ASSERT_EQ(one_shot[c] == egrid::kUnknown, inserted[c] == egrid::kUnknown) << "cell " << c;
    ASSERT_EQ(one_shot[c] == egrid::kUnknown, updates[c] == 0) << "cell " << c;
    if (one_shot[c] == egrid::kUnknown) continue;
    ++known;
    if (left_range[c] || one_shot[c] < 0.01f || one_shot[c] > 0.99f) continue;
    ++compared;
    const double n = updates[c];
    const double bound = (6.6e-5 + 2 * (n - 1) * u * n * t) / 4 + 2 * u;
    tight += bound < 0.1 * t / 4;  // a tenth of one update's move of p, at most
    if (std::fabs(double(one_shot[c]) - double(inserted[c])) > bound && ++beyond <= 5)
      ADD_FAILURE() << "cell " << c << " (" << updates[c] << " updates): one call " << one_shot[c]
                    << ", inserts " << inserted[c] << ", bound " << bound;
  }
  EXPECT_GT(compared, known / 2) << "the bound must cover most known cells to mean anything";
  EXPECT_GT(tight, compared * 9 / 10) << "the bound must be far below one update's step to mean anything";
  EXPECT_EQ(beyond, 0u) << "of " << compared << " cells in [0.01, 0.99]";
}

TEST(MapperSession, ReadsAWindowOfTheGrid) {
  const Fixture f = fr079(50);
  Mapper m(f.params);
  m.insert(f.scans);
  const std::vector<float> all = m.read();
  const GridWindow w{m.frame().size_x / 2 - 10, m.frame().size_y / 2 - 5, 20, 12};
  const std::vector<float> win = m.read(w);
  ASSERT_EQ(win.size(), 240u);
  for (int x = 0; x < w.width; ++x)
    for (int y = 0; y < w.height; ++y)
      ASSERT_EQ(win[static_cast<size_t>(x) * w.height + y],
                all[static_cast<size_t>(w.x0 + x) * m.frame().size_y + (w.y0 + y)]);
  EXPECT_THROW(m.read(GridWindow{m.frame().size_x - 5, 0, 10, 10}), vasco::Error);
  EXPECT_THROW(m.read(GridWindow{-1, 0, 1, 1}), vasco::Error);
  EXPECT_THROW(m.read(GridWindow{INT_MAX, 0, INT_MAX, 1}), vasco::Error);
}

// finish as OccupancyGrid data on the CPU (the renderers' default: finish,
// then the host's conversion), in the session's frame and in a grown grid
// (finished in strips from the grid's window).
TEST(MapperSession, FinishOccupancyIsTheConversionOfTheFinish) {
  const Fixture f = fr079(300);
  for (const char *backend : {"cpu_double", "cpu_float"}) {
    Mapper m(f.params, backend);
    m.insert(f.scans);
    testing_support::expect_occupancy_of_finish(m, 1, 20, backend);
    testing_support::expect_occupancy_of_finish(m, 3, 0, backend);
  }
  Mapper grown(f.params, "cpu_float");
  for (size_t a = 0; a < 300; a += 30) grown.insert(part(f.scans, a, a + 30));
  ASSERT_NE(grown.grid_frame().size_x, grown.frame().size_x) << "the grid did not grow: the case is not tested";
  testing_support::expect_occupancy_of_finish(grown, 1, 20, "cpu_float grown");
}

TEST(MapperSession, ErrorsLeaveTheSessionAsItWas) {
  const Fixture f = fr079(30);
  Mapper m(f.params);
  EXPECT_THROW(m.finish(), vasco::Error);
  m.insert(f.scans);
  const std::vector<float> before = m.read();
  const GridGeometry geo = m.frame();
  EXPECT_THROW(m.render(std::vector<Pose>(3)), vasco::Error);
  // A scan 10^7 m away: the PROTOCOL frame would be far too large.
  ScanBatch far = part(f.scans, 0, 1);
  far.x[0] += 1e7;
  EXPECT_THROW(m.insert(far), std::runtime_error);
  std::vector<Pose> poses = m.poses();
  poses.back().x += 1e7;
  EXPECT_THROW(m.render(poses), std::runtime_error);
  EXPECT_EQ(m.num_scans(), 30u);
  EXPECT_EQ(m.frame().size_x, geo.size_x);
  EXPECT_EQ(m.poses()[29].x, f.scans.x[29]);
  testing_support::expect_bit_identical(before, m.read(), geo, "after the errors");
  MapperParams bad = f.params;
  bad.p_occ = 1.5;
  EXPECT_THROW(Mapper m2(bad), std::exception);
  EXPECT_THROW(Mapper m3(f.params, "gpu9000"), vasco::Error);
}

}  // namespace
}  // namespace vasco
