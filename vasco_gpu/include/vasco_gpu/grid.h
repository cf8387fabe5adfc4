// grid.h — grid sizing (DESIGN §3 step 2) and the finishing step that
// downsamples and crops an evidence grid (DESIGN §2 step 7).
#ifndef VASCO_GPU_GRID_H
#define VASCO_GPU_GRID_H

#include <climits>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace vasco {

struct MapperParams;
struct ScanBatch;
namespace oracle {
struct GridFrame;  // vasco_gpu/internal/oracle.h
}

// Where the evidence grid lies: its size and the first scan's pose, which
// fixes the frame (theta_offset = the first scan's heading, so the grid axes
// are the world axes).
//
// With centre_given, (x0, y0, theta_offset) is that pose instead of scan 0's
// of the batch a renderer is given: every renderer places scans as CARMEN
// does after a first update at (x0, y0, theta_offset), so the grid's axes
// are the world's and its centre is (x0, y0) whatever the scans' poses (a
// Mapper's fixed frame at a given centre, mapper.hpp).
struct GridGeometry {
  int size_x = 0, size_y = 0;
  double resolution = 0;
  double theta_offset = 0;
  double x0 = 0, y0 = 0;  // world position of the first used scan's laser, or the given centre
  bool centre_given = false;

  uint64_t num_cells() const { return static_cast<uint64_t>(size_x) * static_cast<uint64_t>(size_y); }
  // World coordinates of the lower-left corner of cell (gx, gy).
  double world_x(double gx) const { return (gx - size_x / 2.0) * resolution + x0; }
  double world_y(double gy) const { return (gy - size_y / 2.0) * resolution + y0; }
};

// The largest side of an evidence grid, in cells: 2^31 - 1024. Sizes are
// int (CARMEN's map format has int sizes), and the GPU kernels round a side
// up to whole tiles in int (side + 31), which this leaves room for. There is
// no cap on the number of cells: every cell index and count is 64-bit
// (size_x * size_y < 2^62), and a grid is limited by the memory it needs —
// the session's host budget (BackendOptions::max_memory_bytes, checked by the
// Mapper before anything is allocated) and, for a grid on a GPU, the
// device's free memory when the grid is allocated. Both refusals name the
// need.
constexpr int kMaxGridSide = INT32_MAX - 1023;

// How far the scans of a batch lie from its first scan: what the PROTOCOL
// frame is sized by, kept up to date scan by scan by a mapping session.
struct PoseExtent {
  size_t scans = 0;
  double x0 = 0, y0 = 0, theta0 = 0;  // the first scan's laser pose
  double mx = 0, my = 0;              // max |x - x0|, max |y - y0|
  size_t far_x = 0, far_y = 0;        // the scans where they are reached
  // Adds scans [first, last) of `batch` (scan 0 of the batch is the first
  // scan when the extent is empty).
  void add(const ScanBatch &batch, size_t first, size_t last);
  // Adds one pose, scan `index` of the batch it belongs to.
  void add_pose(double x, double y, double theta, size_t index);
};

// How far a batch's poses spread, for messages about the grid they need:
// "the poses span 798 m x 12 m (from the scan at line 1 to line 9 in x and
// line 4 in y)", lines from batch.line (scan indices where it has none).
std::string pose_span_text(const PoseExtent &extent, const ScanBatch &batch);

// Sizes the grid for a batch (DESIGN §3 step 2): the PROTOCOL frame, the one
// function log2map's input and every Mapper size their grid with. Throws
// vasco::Error(BadInput) when the batch is empty, Error(TooLarge) when a side
// would pass kMaxGridSide (naming the source lines of the first and the
// farthest scans). Whether the grid fits in memory is the Mapper's check.
GridGeometry size_grid(const ScanBatch &batch, const MapperParams &params);
GridGeometry size_grid(const PoseExtent &extent, const ScanBatch &batch, const MapperParams &params);

// The oracle's frame of a grid of `geo` with the start pose recorded from
// scan 0 of `batch` (when it has one), as CARMEN's first update records it,
// or from (x0, y0, theta_offset) when geo.centre_given: what every backend
// places scans [first, last) of a batch with, for any first. The one
// GridGeometry -> oracle::GridFrame conversion.
oracle::GridFrame start_frame(const GridGeometry &geo, const ScanBatch &batch);

// The result of finish: a downsampled, cropped grid.
struct FinishedMap {
  int size_x = 0, size_y = 0;
  double resolution = 0;
  int min_x = 0, min_y = 0;   // crop offset, in downsampled cells
  int downsample = 1;
  std::vector<float> cells;   // x-major: cells[x * size_y + y]; -1 unknown
};

// CARMEN's finish (DESIGN §2 step 7): block means of known cells (summed in
// double), crop to the known bounding box plus `border`, new size max - min
// (no +1), resolution times `downsample`. The bounds are 64-bit, so any
// border (INT_MAX included) crops to the grid instead of overflowing; for
// borders CARMEN's int arithmetic holds they are CARMEN's. Throws
// vasco::Error(Usage) for a downsample < 1 or border < 0.
FinishedMap finish_grid(const float *cells, int size_x, int size_y, double resolution,
                        int downsample, int border);

// The same finish of a grid read a strip of whole columns at a time:
// columns(x0, width) returns columns [x0, x0 + width) (x-major, width *
// size_y cells), valid until its next call. Asks for strips of about
// `strip_cells` cells (at least one block column, downsample * size_y), so
// that a grid kept elsewhere (a GPU, a grown session's window) is finished
// without a copy of it in host memory. The same bytes as finish_grid.
using ColumnStrip = std::function<const float *(int x0, int width)>;
FinishedMap finish_grid_by_columns(const ColumnStrip &columns, int size_x, int size_y, double resolution,
                                   int downsample, int border, uint64_t strip_cells);

}  // namespace vasco

#endif  // VASCO_GPU_GRID_H
