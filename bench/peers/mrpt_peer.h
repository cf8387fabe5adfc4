// mrpt_peer.h — MRPT's COccupancyGridMap2D beside ours (mrpt_peer.cc), defined only where peer_bench is
// built with libmrpt-maps-dev (VASCO_HAVE_MRPT); its callers are compiled under the same condition.
#ifndef VASCO_BENCH_PEERS_MRPT_PEER_H
#define VASCO_BENCH_PEERS_MRPT_PEER_H

#include <string>

#include "peer_support.h"

namespace peers {

// Every scan of the job inserted, a warm-up and job.runs timed runs: the row (the median); *counts gets the
// last run's cells.
Row run_mrpt(const Job &job, CellCounts *counts);
// The target's rounds (HeadToHead): cpu_float's render, MRPT's insertion and log2map's map phase in turn.
HeadToHead head_to_head(const Job &job, const std::string &log2map, int rounds);
// MRPT's per-beam update at parameters p, as probabilities (the nearest its int8 log-odds allow).
void mrpt_update_probs(const vasco::MapperParams &p, double *p_occ, double *p_emp);

}  // namespace peers

#endif  // VASCO_BENCH_PEERS_MRPT_PEER_H
