#include "vasco_gpu/pipeline/session_align.h"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "vasco_gpu/grid.h"
#include "vasco_gpu/mapper.hpp"

namespace vasco {

namespace {

// A session's map on the CPU, as align_maps reads it. Every scan counts:
// the run's selection (vasco_first_scan, vasco_num_scans) is of the merged
// sessions and made afterwards.
AlignMap cpu_map_of(const ScanBatch &scans, const MapperParams &params, int threads) {
  MapperParams all = params;
  all.first_scan = 0;
  all.num_scans = -1;
  BackendOptions options;
  options.threads = threads;
  Mapper mapper(all, "cpu_threads", options);
  mapper.insert(scans);
  return align_map_of(mapper.finish(), mapper.frame());
}

std::string candidate_text(const AlignCandidate &c) {
  char text[160];
  std::snprintf(text, sizeof text, "(%.17g, %.17g, %.17g) score %.3f", c.x, c.y, c.theta, c.score);
  return text;
}

}  // namespace

double session_match_resolution(const MapperParams &params) { return std::max(0.1, params.map_resolution()); }

AlignResult align_session(const ScanBatch &reference, const ScanBatch &moving, const MapperParams &params,
                          const std::optional<AlignHint> &hint, int threads) {
  return align_session_to(cpu_map_of(reference, params, threads), moving, params, hint, threads);
}

AlignResult align_session_to(const AlignMap &reference, const ScanBatch &moving, const MapperParams &params,
                             const std::optional<AlignHint> &hint, int threads) {
  const AlignMap mov = cpu_map_of(moving, params, threads);
  AlignOptions options;
  options.match_resolution = session_match_resolution(params);
  options.hint = hint;
  options.threads = threads;
  return align_maps(reference, mov, options);
}

std::string align_candidates_text(const AlignResult &r) {
  std::string text = r.reason.empty() ? std::string(align_verdict_name(r.verdict)) : r.reason;
  text += "; best " + candidate_text(r.best);
  text += r.has_second ? ", second " + candidate_text(r.second) : ", no second candidate";
  return text;
}

}  // namespace vasco
