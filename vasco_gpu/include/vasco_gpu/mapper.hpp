// mapper.hpp — vasco::Mapper, the mapping session every interface uses
// (DESIGN §7): scans stored once, poses replaceable as a whole, an evidence
// grid kept between calls by a renderer of the chosen backend.
//
//   vasco::Mapper m(params, "cuda");       // or cpu_double, cpu_threads, cpu_float
//   m.insert(scans);                        // new scans continue the current grid
//   m.render(poses);                        // a loop closure: every pose moved, recomputed
//   vasco::FinishedMap map = m.finish();    // CARMEN's finish (downsample, crop)
//
// Exactness. With cpu_double, cpu_threads and CUDA exact mode the grid after
// inserting scans 0..k in any number of calls is bit-identical to mapping
// 0..k at once, and a render with poses P is bit-identical to a fresh map of
// a log carrying P (and so, for a CARMEN log, to CARMEN's map) — with the
// one reservation below for a grid that grew.
//
// The grid frame. By default frame() is the golden PROTOCOL's (DESIGN §3) of
// the stored scans: centred on the first scan's pose, 2 * ceil((max |x - x0|
// + range_max + res) / res) + 2 cells wide (likewise in y), theta_offset =
// the first scan's heading — what log2map uses, so its maps stay CARMEN's.
// read(), finish() and frame() always speak of that frame. The renderer's
// grid is that frame on the first insert and after every render(); an insert
// whose scans leave the grid grows it, in each axis that must grow, to the
// larger of what they need and 1.5 times the current half-width (falling back
// to what they need where the margin would pass kMaxGridSide or the memory
// budget), so n inserts of a robot driving away cost O(log n) full renders,
// not n. Not in a session holding a beam whose end cell is 2^29 cells away or
// more (a -inf or huge negative range: CARMEN's wrapping end cell depends on
// the start cell's absolute index): it grows exactly to what it needs. frame() lies centred in a grown grid (whole cells of margin, the
// same first scan and heading), read() returns its window and finish()
// finishes that window, so the margin is never seen. The reservation: in a
// grown grid a scan's cell position is size/2 + d rounded at the grid's size,
// not the final frame's, so a scan position or a beam end lying within a
// rounding step of a cell boundary (poses and ranges on a 1 mm or 1 cm
// lattice often do) can fall one cell over (a scan: with all its beams).
// Exactly: read() is the frame()'s window of a fresh render in grid_frame().
// Measured (`make golden`, the session fed
// in pieces of 97 scans: golden_check's mapper-grown/cpu_threads): 20 of the
// 27 public golden cases are CARMEN's bytes; in the other 7 up to 0.13% of
// the cells change class (fr101 raw: 4370 cells, max |dp| 0.17; paper
// parameters: 0.41). render(poses()) renders in frame() itself, without a
// margin, and gives CARMEN's bytes again (mapper/cpu_threads: 27 of 27). A fixed frame
// (given size, resolution and heading; centred on the first scan, as CARMEN's
// egrid.c) never changes: cells outside it are skipped, as CARMEN skips them.
// A fixed frame at a given centre (frame.centre_given: a grid at a place
// chosen in advance, the ROS node's map_size and map_origin) is centred on
// (frame.x0, frame.y0) with the world's axes, whatever the scans' poses:
// its grid is bit for bit the fixed frame's whose first scan lies at
// (x0, y0) heading theta_offset (theta_offset itself then moves nothing).
// Inserts, render(), start_over and the restore after a failed call all keep
// that centre; frame() reports it from construction on.
//
// Failures. A failed call (vasco::Error with its code, or std::bad_alloc)
// leaves the session as it was: scans, poses, frame and grid. Everything that
// can be checked is checked before anything changes; when a renderer fails
// after the grid changed, the stored state is restored and the grid rendered
// again from it. Should that render fail too, finish() and read() refuse with
// Error(State) until an insert or render() has rendered the grid again: a
// map that does not match the stored scans is never returned.
//
// auto. A session on "auto" runs cuda or cpu_threads by backend_choice.h's
// rule. With options.expected_renders N >= 1 (the default 1) it chooses at its
// first insert, that insert's scans being the workload: a Mapper fed a log
// and finished chooses as log2map does for that log. Until then
// backend_name() is "auto" and memory_need() counts a host grid; a first
// insert that fails leaves it undecided. With N = 0 (a workload without end)
// it chooses when it is made. auto_choice() says what it chose and why.
//
// Threads: a Mapper is one session; calls on one Mapper from several threads
// must be serialized by the caller (the C API's handle does it).
#ifndef VASCO_GPU_MAPPER_HPP
#define VASCO_GPU_MAPPER_HPP

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vasco_gpu/backend.h"
#include "vasco_gpu/backend_choice.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/renderer.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

class Mapper {
 public:
  // PROTOCOL frame. Throws for bad parameters or an unknown backend, and when
  // the backend cannot run here (the registry's errors); Error(Usage) for
  // options.threads outside 0 (all cores) .. kMaxThreads (1024) or a
  // negative options.expected_renders.
  Mapper(const MapperParams &params, const std::string &backend = "cpu_double",
         const BackendOptions &options = {});
  // Fixed frame: `frame.size_x`, `size_y`, `resolution` (must equal
  // params.resolution) and `theta_offset` (finite) are used; x0 and y0 are
  // taken from the first scan, or, with `frame.centre_given`, are the
  // frame's centre (finite; see "A fixed frame at a given centre" above).
  // Error(Usage) for a bad frame, Error(TooLarge) for a side beyond
  // kMaxGridSide (the memory it needs is checked by the first insert,
  // against the budget then in force).
  Mapper(const MapperParams &params, const GridGeometry &frame, const std::string &backend,
         const BackendOptions &options = {});
  // PROTOCOL frame on a renderer of the caller's (a backend of its own).
  Mapper(const MapperParams &params, std::unique_ptr<Renderer> renderer, const BackendOptions &options = {});
  // Fixed frame (as above) on a renderer of the caller's, which places scans
  // by start_frame (grid.h) to honour frame.centre_given.
  Mapper(const MapperParams &params, const GridGeometry &frame, std::unique_ptr<Renderer> renderer,
         const BackendOptions &options = {});

  // Stores `scans` (ranges, beam geometry and poses) after those stored and
  // applies them to the current grid. Throws, storing nothing:
  // Error(BadInput) for a batch whose arrays disagree or a non-finite pose
  // (ScanBatch::validate_for_mapping, naming the scan), Error(TooLarge) when
  // the frame would be too large, Error(OutOfMemory) when the session would
  // need more host memory than the budget (memory_need()), or a GPU's grid
  // more than the device has free. The && form takes the batch's
  // arrays instead of copying them into an empty session (given back on a
  // failure).
  void insert(const ScanBatch &scans);
  void insert(ScanBatch &&scans);
  // New poses for every stored scan (poses.size() == num_scans(), else
  // Error(Usage); a non-finite pose: Error(BadInput) naming it), and the grid
  // recomputed from scratch with them in their PROTOCOL (or the fixed) frame.
  void render(const std::vector<Pose> &poses);

  // CARMEN's finish; Error(State) before any insert, Error(Usage) for a
  // downsample < 1 or a negative border (any larger border crops to the grid).
  FinishedMap finish() const { return finish(static_cast<int>(params_.downsample), static_cast<int>(params_.border)); }
  FinishedMap finish(int downsample, int border) const;
  // The same finish as nav_msgs/OccupancyGrid data by `values`
  // (carmen_compat/occupancy_grid.h), written into out(n) once the map's n
  // cells are known; returns the finished map with its cells left empty. On
  // a GPU the conversion runs there and one byte a cell crosses the bus (the
  // ROS node's /map); the bytes are occupancy_grid_data's of finish().
  FinishedMap finish_occupancy(const carmen::OccupancyValues &values, const OccupancyOut &out, int downsample,
                               int border) const;
  // Error(Usage) for a window not inside frame(), Error(State) before any insert.
  std::vector<float> read(const GridWindow &window) const;
  std::vector<float> read() const;  // the whole full-resolution grid

  // A new session on the same backend: the stored scans, their frame and
  // the grid dropped, `params` in force (checked first: a refusal changes
  // nothing; a fixed frame stays, and its resolution must equal the new
  // vasco_resolution). The renderer is kept, with its GPU context and
  // scratch: a batch of logs pays the backend's start-up once.
  void start_over(const MapperParams &params);

  // A new host-memory budget (0: none). Error(OutOfMemory), keeping the old
  // one, when the session already needs more.
  void set_max_memory_bytes(uint64_t bytes);
  // The host memory, in bytes, the session needs at most with a grid of
  // `geo` and `beams` stored beams: what inserts and renders check against
  // the budget (the renderer's bytes a cell, RendererTraits, the finish at
  // vasco_downsample, 68 bytes a beam). memory_need() is the current one.
  double memory_need(const GridGeometry &geo, uint64_t beams) const;
  double memory_need() const { return memory_need(grid_, scans_.num_beams()); }

  size_t num_scans() const { return scans_.num_scans(); }
  const ScanBatch &scans() const { return scans_; }
  std::vector<Pose> poses() const;
  const GridGeometry &frame() const { return geo_; }
  // The renderer's grid: frame() itself, or after growth frame() centred in
  // whole cells of margin (the same first scan and heading). With an exact
  // backend read() is the frame()'s window of a fresh render of the stored
  // scans in this grid, byte for byte.
  const GridGeometry &grid_frame() const { return grid_; }
  const MapperParams &params() const { return params_; }
  // The renderer's name; "auto" while an auto session has not chosen.
  std::string backend_name() const { return renderer_ ? renderer_->name() : "auto"; }
  // What the backend is: exact or not, grid on the GPU or in host memory
  // (an auto session that has not chosen: cpu_threads', a host grid).
  RendererTraits backend_traits() const;
  // What an auto session chose and why; null for another backend and while
  // undecided.
  const AutoChoice *auto_choice() const { return auto_choice_ ? &*auto_choice_ : nullptr; }
  // Counts and times of the last insert or render (a growth re-render included).
  const MapStats &last_stats() const { return stats_; }
  // Full renders since construction: one per render(), per growth, the first
  // insert, and one per restore after a renderer failed.
  size_t renders() const { return renders_; }

 private:
  // What an insert will do, decided before anything changes.
  struct InsertPlan {
    PoseExtent extent;
    GridGeometry geo, grid;
    bool full_render = false;
    bool shift_invariant = true;
  };
  // What a failed call restores.
  struct Saved {
    size_t scans;
    GridGeometry geo, grid;
    PoseExtent extent;
    MapStats stats;
    bool shift_invariant;
  };

  // The renderer of an auto session still undecided, chosen for `scans`;
  // whether it was chosen now (a failed insert undoes that: undo_choice).
  bool choose_renderer(const ScanBatch &scans);
  void undo_choice() noexcept;
  GridGeometry frame_for(const PoseExtent &extent, const ScanBatch &scans) const;
  GridGeometry grown_frame(const GridGeometry &need, uint64_t beams) const;
  bool fits_memory(const GridGeometry &geo, uint64_t beams) const;
  void check_memory(const GridGeometry &geo, uint64_t beams) const;
  void check_grid_usable(const char *what) const;
  // finish's and finish_occupancy's checks, naming `what`; whether the
  // renderer's grid is frame() itself (not grown with a margin around it).
  bool finishes_whole_grid(const char *what, int downsample, int border) const;
  GridWindow frame_window() const;  // frame()'s cells in the renderer's grid
  InsertPlan plan_insert(const ScanBatch &scans) const;
  void apply_insert(const InsertPlan &plan, size_t before);
  Saved save() const { return Saved{scans_.num_scans(), geo_, grid_, extent_, stats_, shift_invariant_}; }
  void restore(const Saved &saved) noexcept;
  void rerender();

  MapperParams params_;
  BackendOptions options_;
  bool fixed_frame_ = false;
  GridGeometry geo_;   // frame(): the PROTOCOL frame of the stored scans, or the fixed one
  GridGeometry grid_;  // what the renderer holds: geo_, or geo_ with a margin after growth
  ScanBatch scans_;
  PoseExtent extent_;  // of the stored scans' poses
  std::unique_ptr<Renderer> renderer_;  // null: an auto session that has not chosen
  std::optional<AutoChoice> auto_choice_;
  MapStats stats_;
  size_t renders_ = 0;
  bool grid_lost_ = false;        // a failed restore: the grid does not match the stored scans
  bool shift_invariant_ = true;  // no stored beam's end can wrap: a margin is allowed
};

}  // namespace vasco

#endif  // VASCO_GPU_MAPPER_HPP
