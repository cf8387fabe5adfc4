// Beam placement: the end cells place_beams derives without a cos and a sin
// per beam are, beam for beam, the ones the oracle's beam_end computes with
// the host's libm, on the bundled logs, on random scans, and on scans built
// so that many beams end within 1e-9 of a cell border (where only the
// oracle's own rounding decides the cell).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "test_seed.h"
#include "test_support.h"
#include "vasco_gpu/internal/beam_placement.h"
#include "vasco_gpu/internal/oracle.h"

namespace vasco {
namespace {

// The oracle's sequential placement of every used beam, written out with
// beam_end (glibc's cos and sin per beam) as egrid.c places them.
std::vector<PlacedBeam> oracle_placement(const ScanBatch &batch, const GridGeometry &geo,
                                         const MapperParams &params, size_t *near_border = nullptr) {
  const std::vector<oracle::ScanStart> starts = place_scans(batch, geo);
  std::vector<PlacedBeam> out;
  for (size_t s = 0; s < batch.num_scans(); ++s) {
    oracle::SteppedAngles angles{batch.first_angle[s], batch.angle_step[s]};
    const float *r = batch.ranges_of(s);
    double angle = 0;
    for (int b = 0; b < batch.beams_in(s); ++b) {
      angles(b, starts[s].theta, &angle);
      if (!oracle::beam_used(r[b])) continue;
      PlacedBeam p{};
      oracle::beam_end(starts[s], angle, r[b], params.wall_size, geo.resolution, &p.x2, &p.y2);
      p.scan = static_cast<uint32_t>(s);
      p.range = r[b];
      out.push_back(p);
      if (near_border) {
        const double k = (static_cast<double>(r[b]) + params.wall_size) / geo.resolution;
        for (double v : {starts[s].lx + k * std::cos(angle), starts[s].ly + k * std::sin(angle)})
          if (std::isfinite(v) && std::fabs(v - std::nearbyint(v)) < 1e-9) ++*near_border;
      }
    }
  }
  return out;
}

void expect_same_beams(const std::vector<PlacedBeam> &want, const std::vector<PlacedBeam> &got) {
  ASSERT_EQ(got.size(), want.size());
  size_t differ = 0;
  for (size_t i = 0; i < want.size(); ++i) {
    const PlacedBeam &a = want[i], &b = got[i];
    if (a.x2 != b.x2 || a.y2 != b.y2 || a.scan != b.scan || std::memcmp(&a.range, &b.range, 4) != 0) {
      if (++differ <= 5)
        ADD_FAILURE() << "beam " << i << " of scan " << a.scan << ": oracle (" << a.x2 << ", " << a.y2
                      << "), placed (" << b.x2 << ", " << b.y2 << ")";
    }
  }
  EXPECT_EQ(differ, 0u);
}

// place_beams on `threads` cores, and ScanBeamPlacer a scan at a time (one
// placer for every scan, as cpu_float places them): the oracle's beams.
void expect_same_placement(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
                           int threads) {
  const std::vector<PlacedBeam> want = oracle_placement(batch, geo, params);
  {
    SCOPED_TRACE("place_beams");
    expect_same_beams(want, place_beams(batch, geo, params, threads).beams);
  }
  SCOPED_TRACE("ScanBeamPlacer");
  const std::vector<oracle::ScanStart> starts = place_scans(batch, geo);
  ScanBeamPlacer placer;
  std::vector<PlacedBeam> streamed, one;
  for (size_t s = 0; s < batch.num_scans(); ++s) {
    one.assign(static_cast<size_t>(batch.beams_in(s)), PlacedBeam{});
    const size_t n = placer.place(batch, geo, params, starts[s], s, static_cast<uint32_t>(s), one.data());
    streamed.insert(streamed.end(), one.begin(), one.begin() + static_cast<std::ptrdiff_t>(n));
  }
  expect_same_beams(want, streamed);
}

TEST(BeamPlacement, EndCellsOfTheBundledLogsAreTheOracles) {
  for (const char *log : {"fr079-complete.gfs.log.gz", "intel.gfs.log.gz", "fr101.carmen.log.gz"}) {
    SCOPED_TRACE(log);
    MapperParams params;
    const auto l = testing_support::load_log(testing_support::bundled_log(log), params);
    expect_same_placement(l.batch, l.geo, params, 3);
  }
}

TEST(BeamPlacement, EndCellsOfRandomScansAreTheOracles) {
  const unsigned seed = testing_support::test_seed();
  SCOPED_TRACE("random seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  MapperParams params;
  params.resolution = 0.05;
  const ScanBatch batch = testing_support::random_batch(rng, 400, 20);
  expect_same_placement(batch, size_grid(batch, params), params, 2);
}

// Headings far from zero: the accumulated angle's rounding grows with its
// magnitude, up to where the derived cos and sin give way to the oracle's.
TEST(BeamPlacement, EndCellsAtLargeHeadingsAreTheOracles) {
  std::mt19937 rng(testing_support::test_seed(5));
  std::uniform_real_distribution<double> u(0, 1);
  ScanBatch batch;
  std::vector<float> r(361);
  for (int s = 0; s < 200; ++s) {
    for (auto &v : r) v = static_cast<float>(40 * u(rng));
    const double theta = std::ldexp(u(rng) - 0.5, s % 40);  // up to 2^39 rad
    batch.add_scan(u(rng), u(rng), theta, -M_PI / 2, M_PI / 360, r.data(), 361, s + 1);
  }
  MapperParams params;
  expect_same_placement(batch, size_grid(batch, params), params, 2);
}

// The first pose fixes the frame, so a robot at the start pose has its laser
// on a cell corner. With cells of 0.25 m (exact in binary), a beam in the
// direction of a Pythagorean triple (a, b, c) whose range plus wall is m·c
// cells ends at (a·m, b·m) cells from it, up to the rounding of cos and sin:
// an ulp there decides the cell, and only the oracle's own value is right.
TEST(BeamPlacement, EndCellsOnCellBordersAreTheOracles) {
  std::mt19937 rng(testing_support::test_seed(9));
  std::uniform_int_distribution<int> pick(0, 3), beam(0, 360), mult(1, 6);
  const int triples[4][3] = {{3, 4, 5}, {5, 12, 13}, {8, 15, 17}, {7, 24, 25}};
  MapperParams params;
  params.resolution = 0.25;
  params.wall_size = 0.25;
  const double step = M_PI / 360;
  ScanBatch batch;
  std::vector<float> r(361);
  for (int s = 0; s < 3000; ++s) {
    const int *t = triples[pick(rng)];
    const int m = mult(rng), target = beam(rng);
    for (auto &v : r) v = static_cast<float>(0.25 * t[2] * mult(rng) - 0.25);
    r[static_cast<size_t>(target)] = static_cast<float>(0.25 * t[2] * m - 0.25);
    const double heading = std::atan2(t[1], t[0]) + (pick(rng) - 1.5) * 1e-16;
    batch.add_scan(0, 0, s == 0 ? 0 : heading, -target * step, step, r.data(), 361, s + 1);
  }
  const GridGeometry geo = size_grid(batch, params);
  size_t near_border = 0;
  oracle_placement(batch, geo, params, &near_border);
  ASSERT_GT(near_border, 3000u) << "the scans no longer put beams on cell borders";
  expect_same_placement(batch, geo, params, 2);
}

}  // namespace
}  // namespace vasco
