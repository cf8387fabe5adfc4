// peer_support.h — what peer_bench's files share (peer_bench.cc: our backends, OctoMap and the printout;
// mrpt_peer.cc: MRPT and the target's rounds against it): a job, a table row, cell counts.
#ifndef VASCO_BENCH_PEERS_PEER_SUPPORT_H
#define VASCO_BENCH_PEERS_PEER_SUPPORT_H

#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "../bench_support.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/pipeline/log_scans.h"

namespace peers {

const char *const kMrptLabel = "MRPT COccupancyGridMap2D";
const char *const kOctomapLabel = "OctoMap OcTree";

// Cells of a map on either side of even odds; unknown cells (and any exactly at 0.5) are in neither.
struct CellCounts {
  uint64_t occupied = 0, free = 0;
};

// One table row; map_s < 0 when the mapper was not built (`missing` says what to install).
struct Row {
  std::string data, params, mapper, missing;
  uint64_t scans = 0, beams = 0;
  double map_s = -1;
  double first_s = -1;  // cpu_float: a fresh renderer's first apply (first_render_seconds)
};

// What every mapper of one log and parameter set shares: the scans, parameters and our grid.
struct Job {
  std::string data, params;
  std::string log_path, log2map_args;  // the log and the parameters as log2map takes them (its map phase)
  vasco::MapperParams p;
  vasco::ScanBatch batch;
  vasco::GridGeometry geo;
  int runs = 3;
};

// cpu_float beside MRPT for the target, round by round: a round times cpu_float's render (a warm
// renderer, as its table row), MRPT's insertion (a grid allocated beforehand) and log2map's map phase (a
// process of its own) one after the other, so that a drift of this shared machine's speed falls on the
// three alike, and a round's ratio is MRPT's time over ours in that round. The table's rows, each mapper's
// runs in a block, minutes apart, moved MRPT's ratio by a third between two runs of the bench.
struct HeadToHead {
  std::string data, params;
  std::vector<double> render, mrpt, cli;  // seconds, a round each; cli empty without log2map
  double first = -1;                      // a fresh renderer's first render (first_render_seconds)
};

// A beam the peers insert: one with a return. CARMEN skips ranges >= 50 m, NaN and +inf (egrid_math.h);
// -inf, which CARMEN walks as a degenerate beam, has no sensible end point for a peer.
inline bool has_return(float r) { return std::isfinite(r) && vasco::egrid::is_beam_used(r); }

// A warm-up call of `run` (which times its own insertion and returns the seconds), then `runs` timed
// calls: their median.
inline double timed_median(int runs, const std::function<double()> &run) {
  run();
  std::vector<double> t;
  for (int r = 0; r < runs; ++r) t.push_back(run());
  return bench::median(t);
}

inline Row make_row(const Job &job, const std::string &mapper) {
  Row row;
  row.data = job.data;
  row.params = job.params;
  row.mapper = mapper;
  row.scans = job.batch.num_scans();
  return row;
}

// Where a user sees it: log2map's seconds.map (--json) for cpu_float, a
// fresh process per run (its memory touched for the first time, caches
// cold), the median of `runs`; < 0 when log2map is not beside this program
// or fails.
double log2map_map_seconds(const std::string &log2map, const Job &job, int runs);

}  // namespace peers

#endif  // VASCO_BENCH_PEERS_PEER_SUPPORT_H
