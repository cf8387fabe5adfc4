// mrpt_peer.cc — MRPT's COccupancyGridMap2D on peer_bench's jobs (mrpt_peer.h): its insertion options as
// near CARMEN's model as it allows, its grid, its rows, and the target's rounds against cpu_float.
#include "mrpt_peer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "vasco_gpu/backend.h"
#include "vasco_gpu/renderer.h"

#if defined(VASCO_HAVE_MRPT)
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/poses/CPose3D.h>
#endif

namespace peers {

using bench::now_s;

#if defined(VASCO_HAVE_MRPT)
using mrpt::maps::COccupancyGridMap2D;

namespace {

using mrpt::maps::COccupancyGridMap2D;

// MRPT's per-beam updates as probabilities: its int8 log-odds step is 1/16 (CLogOddsGridMapLUT), a free
// update adds max(1, p2l(freeness certainty)) steps and an occupied one subtracts 3 * max(1, p2l(occupancy
// certainty)) (COccupancyGridMap2D_insert.cpp, MRPT 2.5).
void update_probs(const COccupancyGridMap2D::TInsertionOptions &io, double *p_occ, double *p_emp) {
  const int occ = 3 * std::max(1, int(COccupancyGridMap2D::p2l(io.maxOccupancyUpdateCertainty)));
  const int emp = std::max(1, int(COccupancyGridMap2D::p2l(io.maxFreenessUpdateCertainty)));
  *p_occ = 1 / (1 + std::exp(-occ / 16.0));
  *p_emp = 1 / (1 + std::exp(emp / 16.0));
}

// MRPT's insertion options as near ours as its model allows. What differs from CARMEN's model
// (COccupancyGridMap2D_insert.cpp, "simple rays", MRPT 2.5):
//  - a beam frees the cells from the laser to its end cell and marks that one cell occupied; CARMEN
//    marks every cell from the hit to wall_size (0.2 m: 8 cells) behind it occupied;
//  - the evidence is the same at every distance; CARMEN's fades to the prior from range_sure to range_max;
//  - cells hold int8 log-odds in steps of 1/16 (Debian builds MRPT with 8-bit cells), saturating at
//    +-127 steps, so the update is the nearest step to ours (update_probs) and not exact; CARMEN
//    keeps float probabilities updated in double odds;
//  - MRPT multiplies the occupied update by 3: the occupancy certainty below is chosen so that 3 times
//    its log-odds is log-odds(p_occ); the free update is log-odds(p_emp) through the freeness certainty;
//  - like CARMEN, a beam longer than range_max frees the cells up to range_max and marks none (CARMEN's
//    evidence there has faded to the prior), and a cell crossed by several beams of a scan is updated once
//    per beam; there is no range_sure.
void set_mrpt_options(const vasco::MapperParams &p, COccupancyGridMap2D::TInsertionOptions *io) {
  const double logit_occ = std::log(p.p_occ / (1 - p.p_occ));
  io->maxDistanceInsertion = float(p.range_max);
  io->maxOccupancyUpdateCertainty = float(1 / (1 + std::exp(-logit_occ / 3)));
  io->maxFreenessUpdateCertainty = float(1 - p.p_emp);
  io->considerInvalidRangesAsFreeSpace = false;  // CARMEN skips beams without a return
  io->wideningBeamsWithDistance = false;         // CARMEN traces one line per beam
  io->decimation = 1;
  io->useMapAltitude = false;
}

// A grid over our grid's world extent (allocated and cleared here, not in the timed loop).
std::unique_ptr<COccupancyGridMap2D> mrpt_grid(const Job &job) {
  const vasco::GridGeometry &g = job.geo;
  // MRPT grows its grid (a copy of it, inside the timed loop) when an end point comes within 15 cells of
  // an edge; 16 cells more on every side keep it at this size.
  const double margin = 16 * g.resolution;
  auto m = std::make_unique<COccupancyGridMap2D>(
      float(g.world_x(0) - margin), float(g.world_x(g.size_x) + margin), float(g.world_y(0) - margin),
      float(g.world_y(g.size_y) + margin), float(g.resolution));
  set_mrpt_options(job.p, &m->insertionOptions);
  return m;
}

// The scans as MRPT observations and robot poses, built once and not timed (our backends too get
// the parsed batch).
struct MrptScans {
  std::vector<mrpt::obs::CObservation2DRangeScan> obs;
  std::vector<mrpt::poses::CPose3D> poses;
  uint64_t beams = 0;
};

MrptScans mrpt_scans(const vasco::ScanBatch &b) {
  MrptScans m;
  m.obs.resize(b.num_scans());
  for (size_t s = 0; s < b.num_scans(); ++s) {
    const int n = b.beams_in(s);
    const float *r = b.ranges_of(s);
    mrpt::obs::CObservation2DRangeScan &o = m.obs[s];
    o.resizeScan(n);
    // MRPT's insertion spaces n beams aperture / n apart from heading - aperture / 2 (rightToLeft; the
    // mirror image otherwise): aperture = n |step| keeps our spacing, and the heading below puts its beam
    // b on ours (it is our laser heading when the scan is symmetric about it, as MRPT assumes).
    o.aperture = float(n * std::fabs(b.angle_step[s]));
    o.rightToLeft = b.angle_step[s] >= 0;
    o.maxRange = float(vasco::egrid::kLaserRangeLimit);
    o.sensorPose = mrpt::poses::CPose3D();
    for (int i = 0; i < n; ++i) {
      const bool used = has_return(r[i]);
      o.setScanRange(i, used ? r[i] : 0.0f);
      o.setScanRangeValidity(i, used);
      m.beams += used;
    }
    const double heading = b.theta[s] + b.first_angle[s] + 0.5 * n * b.angle_step[s];
    m.poses.emplace_back(b.x[s], b.y[s], 0.0, heading, 0.0, 0.0);
  }
  return m;
}

// The grid stores the probability of being free (raw log-odds > 0: free; getCell gives 1 for free).
CellCounts count_mrpt(const COccupancyGridMap2D &m) {
  CellCounts c;
  for (const auto v : m.getRawMap()) {
    if (v < 0) ++c.occupied;
    else if (v > 0) ++c.free;
  }
  return c;
}

// Every scan inserted into a grid allocated beforehand (the allocation is not timed): the seconds. The
// grid is left in *last; *refused counts the scans MRPT refused.
double mrpt_insert_once(const Job &job, const MrptScans &scans, std::unique_ptr<COccupancyGridMap2D> *last,
                        size_t *refused) {
  last->reset();
  auto m = mrpt_grid(job);
  const unsigned size_x = m->getSizeX(), size_y = m->getSizeY();
  const double t0 = now_s();
  for (size_t s = 0; s < scans.obs.size(); ++s) *refused += !m->insertObservation(scans.obs[s], scans.poses[s]);
  const double t = now_s() - t0;
  if (m->getSizeX() != size_x || m->getSizeY() != size_y)
    std::fprintf(stderr, "peer_bench: MRPT grew its grid during the run (timed)\n");
  *last = std::move(m);
  return t;
}

}  // namespace

Row run_mrpt(const Job &job, CellCounts *counts) {
  const MrptScans scans = mrpt_scans(job.batch);
  Row row = make_row(job, kMrptLabel);
  row.beams = scans.beams;
  std::unique_ptr<COccupancyGridMap2D> last;
  size_t refused = 0;
  row.map_s = timed_median(job.runs, [&] { return mrpt_insert_once(job, scans, &last, &refused); });
  if (refused > 0) std::fprintf(stderr, "peer_bench: MRPT refused %zu scans\n", refused);
  *counts = count_mrpt(*last);
  return row;
}

HeadToHead head_to_head(const Job &job, const std::string &log2map, int rounds) {
  HeadToHead h;
  h.data = job.data;
  h.params = job.params;
  const MrptScans scans = mrpt_scans(job.batch);
  std::unique_ptr<COccupancyGridMap2D> last;
  size_t refused = 0;
  auto renderer = vasco::make_renderer("cpu_float", vasco::BackendOptions{});
  const auto render = [&] {
    const double t0 = now_s();
    renderer->reset(job.geo, job.p);
    renderer->apply(job.batch, 0, job.batch.num_scans(), nullptr);
    return now_s() - t0;
  };
  render();  // the warm-up round: the renderer's table and grid, MRPT's code and pages
  mrpt_insert_once(job, scans, &last, &refused);
  for (int r = 0; r < rounds; ++r) {
    h.render.push_back(render());
    h.mrpt.push_back(mrpt_insert_once(job, scans, &last, &refused));
    const double cli = log2map_map_seconds(log2map, job, 1);
    if (cli > 0) h.cli.push_back(cli);
  }
  if (h.cli.size() != h.render.size()) h.cli.clear();  // log2map absent or failing: no column
  return h;
}

void mrpt_update_probs(const vasco::MapperParams &p, double *p_occ, double *p_emp) {
  COccupancyGridMap2D::TInsertionOptions io;
  set_mrpt_options(p, &io);
  update_probs(io, p_occ, p_emp);
}

#endif  // VASCO_HAVE_MRPT

}  // namespace peers
