// session_align.h — the transforms of sessions added with "@auto"
// (`log2map A.log --add B.log@auto OUT`): each such session, in order, is
// aligned (align.h) to the map of every session before it at its transform,
// given or found, and then mapped as if its transform had been given.
//
// Both maps are made on the CPU (cpu_threads) with the run's parameters and
// matched at 0.1 m (or the map cell where that is coarser). A session the
// alignment refuses (no overlap, or two distinct candidates nearly as good)
// stops the run: a carmen::FileError naming the session's input, the reason
// and the best candidates, before anything is mapped or written.
#ifndef VASCO_GPU_PIPELINE_SESSION_ALIGN_H
#define VASCO_GPU_PIPELINE_SESSION_ALIGN_H

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "vasco_gpu/align.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/pose_series.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

// One added session as mapped: its transform into the shared frame, and for
// an "@auto" session what the alignment found.
struct AddedSession {
  std::string input;
  Pose2 transform;
  bool aligned = false;  // true: found by the alignment ("@auto"); false: given
  AlignResult result;    // only where aligned
  double seconds = 0;    // mapping both sessions and aligning them
};

struct SessionAlignOptions {
  int threads = 0;  // the CPU mapping's and the search's (0: every usable core)
  // Called once a session is aligned (before the next one is): progress lines.
  std::function<void(const AddedSession &)> aligned;
};

// The cell the maps are matched at: 0.1 m, or the map cell where coarser.
double session_match_resolution(const MapperParams &params);

// Aligns `moving` (a session's scans in its own frame) to `reference` (the
// sessions before it, in the shared frame), both mapped with `params` (every
// scan: vasco_first_scan and vasco_num_scans select the run afterwards).
// Never throws for a refusal: the verdict says it.
AlignResult align_session(const ScanBatch &reference, const ScanBatch &moving, const MapperParams &params,
                          const std::optional<AlignHint> &hint, int threads);

// As align_session, the reference already a map (a session's finish(), as
// align_map_of gives it): Mapper.insert(scans, transform="auto") aligns to
// the grid it holds rather than mapping its scans again.
AlignResult align_session_to(const AlignMap &reference, const ScanBatch &moving, const MapperParams &params,
                             const std::optional<AlignHint> &hint, int threads);

// "reason; best (x, y, theta) score s, second (x, y, theta) score s": what a
// refusal says of the candidates.
std::string align_candidates_text(const AlignResult &r);

}  // namespace vasco

#endif  // VASCO_GPU_PIPELINE_SESSION_ALIGN_H
