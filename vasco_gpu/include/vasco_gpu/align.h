// align.h — finding the rigid transform between two sessions' maps: the
// transform T = (x, y, theta) that takes the MOVING map's world frame into
// the REFERENCE map's, in the convention of `log2map --add LOG@X,Y,THETA`
// and ScanBatch::transform: x' = X + cos(THETA) x - sin(THETA) y,
// y' = Y + sin(THETA) x + cos(THETA) y.
//
//   vasco::AlignMap ref = vasco::align_map_of(ref_map, ref_geo);
//   vasco::AlignMap mov = vasco::align_map_of(mov_map, mov_geo);
//   vasco::AlignResult r = vasco::align_maps(ref, mov, {});
//   if (r.verdict == vasco::AlignVerdict::Aligned) second.transform(r.best.x, r.best.y, r.best.theta);
//
// The search (src/align/): every rotation and every translation where the
// maps can overlap, by branch and bound over max-pooled likelihood grids at
// four times the matching cell (on the GPU: every candidate scored, the
// same candidates found), then at the matching cell near the best few
// candidates, then a local refinement to a fraction of a cell. It refuses rather than guesses: a best candidate
// scoring below min_score is "no overlap", and a distinct second candidate
// nearly as good is "ambiguous".
#ifndef VASCO_GPU_ALIGN_H
#define VASCO_GPU_ALIGN_H

#include <optional>
#include <string>
#include <vector>

#include "vasco_gpu/grid.h"

namespace vasco {

// A map to align: cells x-major as FinishedMap's (cells[x * size_y + y]),
// each an occupancy probability in [0, 1] or -1 (unknown; any negative
// value counts as unknown); origin is the world position of cell (0, 0)'s
// lower-left corner, the map's axes the world's.
struct AlignMap {
  int size_x = 0, size_y = 0;
  double resolution = 0;
  double origin_x = 0, origin_y = 0;
  std::vector<float> cells;
};

// A finished map with its world origin (map_output.h's world_origin: the
// grid frame `geo` it was finished from).
AlignMap align_map_of(const FinishedMap &map, const GridGeometry &geo);
AlignMap align_map_of(FinishedMap &&map, const GridGeometry &geo);

// Search only near a guess of T: x and y each within radius_m of the
// guess's (a square, rounded outwards to whole search cells), theta within
// radius_rad.
struct AlignHint {
  double x = 0, y = 0, theta = 0;
  double radius_m = 1.0;
  double radius_rad = 0.1;
};

struct AlignOptions {
  // The cell the maps are matched at, in metres: finer maps are max-pooled
  // to it, coarser ones sampled. The accuracy is a fraction of this cell.
  double match_resolution = 0.1;
  std::optional<AlignHint> hint;
  // The best candidate's score (the mean likelihood of the moving map's
  // occupied cells on the reference, see AlignResult::score) below which the
  // maps are said not to overlap.
  double min_score = 0.15;
  // A distinct second candidate scoring at least ambiguity * best makes the
  // result ambiguous (1 or more: never).
  double ambiguity = 0.9;
  // Fewer occupied moving cells than this matched to reference walls at the
  // best candidate: no overlap.
  int min_matched = 40;
  int threads = 0;  // 0: every usable core
  // Where the global search runs (the finer passes and the verdict run on
  // the CPU either way). Auto, the default, takes the GPU where one is
  // usable: it scores every candidate where the CPU bounds them, and its
  // candidates are the CPU's (the same sums to the bit), so the choice
  // changes the time, not the answer; a GPU that fails (no memory, no
  // device after all) leaves Auto to the CPU. Gpu throws Error(NoGpu) where
  // none is usable.
  enum class Backend { Auto, Cpu, Gpu };
  Backend backend = Backend::Auto;
  int cuda_device = 0;  // the device Auto and Gpu use
};

enum class AlignVerdict { Aligned, NoOverlap, Ambiguous };
const char *align_verdict_name(AlignVerdict v);  // "aligned", "no_overlap", "ambiguous"

struct AlignCandidate {
  double x = 0, y = 0, theta = 0;  // T, theta in (-pi, pi]
  // Mean over the moving map's occupied cells (at match_resolution) of the
  // reference's likelihood at T: 1 on a reference wall, falling off over
  // about a cell, negative on reference cells known free, 0 on unknown
  // ones. The fraction of the moving map's walls that T lays on the
  // reference's walls, less those it lays across its free space.
  double score = 0;
};

struct AlignResult {
  AlignVerdict verdict = AlignVerdict::NoOverlap;
  std::string reason;  // why, for a verdict other than Aligned
  AlignCandidate best;
  // The best candidate that moves the moving map's walls more than a few
  // cells away from where `best` lays them (six matching cells: translation
  // plus rotation times their RMS radius), among the best distinct
  // candidates of the coarse search refined; has_second false when there is
  // none.
  AlignCandidate second;
  bool has_second = false;
  // At `best`: the fraction of the moving map's occupied cells landing on
  // known reference cells, and how many lie on reference walls.
  double overlap = 0;
  int matched = 0;
  int moving_points = 0;  // occupied moving cells at match_resolution
  int rotations = 0;      // rotations searched
  bool gpu = false;       // the global search ran on the GPU
};

// Aligns `moving` to `reference`. Never throws for empty or degenerate maps
// (no occupied cell, no overlap): verdict NoOverlap with a reason. Throws
// vasco::Error(Usage) for bad options (match_resolution not finite and > 0,
// a negative or non-finite hint radius, threads < 0, cuda_device < 0) and Error(BadInput)
// for a map whose cells do not number size_x * size_y or whose resolution
// or origin is not finite; Error(TooLarge) for a map beyond 2^20 cells a
// side or 2^26 cells at the matching cell; Error(NoGpu) for backend Gpu
// without a usable GPU.
AlignResult align_maps(const AlignMap &reference, const AlignMap &moving, const AlignOptions &options = {});

}  // namespace vasco

#endif  // VASCO_GPU_ALIGN_H
