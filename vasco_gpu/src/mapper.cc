#include "vasco_gpu/mapper.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <utility>

#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/error.h"

namespace vasco {
namespace {

void check_window(const GridWindow &w, const GridGeometry &geo) {
  if (w.width < 0 || w.height < 0 || w.x0 < 0 || w.y0 < 0 ||
      static_cast<int64_t>(w.x0) + w.width > geo.size_x || static_cast<int64_t>(w.y0) + w.height > geo.size_y)
    throw Error(ErrorCode::Usage, "Mapper::read: window [" + std::to_string(w.x0) + ", +" +
                                      std::to_string(w.width) + ") x [" + std::to_string(w.y0) + ", +" +
                                      std::to_string(w.height) + ") is not inside the " +
                                      std::to_string(geo.size_x) + " x " + std::to_string(geo.size_y) + " grid");
}

void check_fixed_frame(const GridGeometry &frame, const MapperParams &params) {
  if (frame.size_x <= 0 || frame.size_y <= 0)
    throw Error(ErrorCode::Usage, "Mapper: a fixed frame needs a size of at least 1 x 1 cells");
  if (frame.size_x > kMaxGridSide || frame.size_y > kMaxGridSide)
    throw Error(ErrorCode::TooLarge, "Mapper: a fixed frame of " + std::to_string(frame.size_x) + " x " +
                                         std::to_string(frame.size_y) + " cells is beyond the limit of " +
                                         std::to_string(kMaxGridSide) + " cells a side");
  if (frame.resolution != params.resolution)
    throw Error(ErrorCode::Usage, "Mapper: the frame's resolution differs from vasco_resolution");
  if (!std::isfinite(frame.theta_offset))
    throw Error(ErrorCode::Usage, "Mapper: the fixed frame's theta_offset is not finite");
  if (frame.centre_given && !(std::isfinite(frame.x0) && std::isfinite(frame.y0)))
    throw Error(ErrorCode::Usage, "Mapper: the fixed frame's given centre (x0, y0) is not finite");
}

void check_poses(const std::vector<Pose> &poses) {
  for (size_t s = 0; s < poses.size(); ++s)
    if (!std::isfinite(poses[s].x) || !std::isfinite(poses[s].y) || !std::isfinite(poses[s].theta))
      throw Error(ErrorCode::BadInput, "Mapper::render: pose " + std::to_string(s) + " is not finite");
}

// A renderer keeps per-thread scratch: a count far beyond any machine's cores
// would exhaust memory inside an insert, so it is refused up front.
void check_threads(int threads) {
  if (threads < 0 || threads > kMaxThreads)
    throw Error(ErrorCode::Usage, "Mapper: threads = " + std::to_string(threads) + " is outside 0 (all cores) .. " +
                                      std::to_string(kMaxThreads));
}

void check_options(const BackendOptions &options) {
  check_threads(options.threads);
  if (options.expected_renders < 0)
    throw Error(ErrorCode::Usage, "Mapper: expected_renders = " + std::to_string(options.expected_renders) +
                                      " is negative (0: a workload without end)");
}

// The renderer a session on `backend` starts with: null for auto with
// expected renders (it chooses at its first insert, by the workload);
// `choice` is set when auto chose now.
std::unique_ptr<Renderer> first_renderer(const std::string &backend, const BackendOptions &options,
                                         std::optional<AutoChoice> *choice) {
  BackendOptions o = options;
  const BackendInfo *b = find_backend(resolve_backend_name(backend, &o));
  if (!b->chooses) return make_renderer(backend, options);
  if (options.expected_renders > 0) return nullptr;
  AutoChoice c = choose_auto(nullptr, MapperParams{}, o);
  std::unique_ptr<Renderer> r = make_renderer(c.backend, o);
  *choice = std::move(c);
  return r;
}

// Whether every used beam of `scans` ends a safe number of cells from its
// start: then the end cell never wraps CARMEN's 32-bit ints and a scan maps
// to the same cells, shifted, in a larger grid. A -inf or huge negative range
// ends at INT_MIN, and CARMEN's wrapping x2 - x1 then depends on the start
// cell's absolute index: such sessions grow without a margin.
bool beams_shift_invariant(const ScanBatch &scans, const MapperParams &params) {
  const double limit = static_cast<double>(1 << 29) * params.resolution;
  for (float r : scans.range)
    if (egrid::is_beam_used(r) && !(std::fabs(static_cast<double>(r) + params.wall_size) < limit)) return false;
  return true;
}

// One axis of a grown PROTOCOL frame: as wide as needed, and at least half
// as wide again as now (sizes are 2 * half + 2), in 64 bits.
int64_t grown_size(int need, int current) {
  if (need <= current) return current;
  const int64_t half_now = (current - 2) / 2, half_need = (need - 2) / 2;
  return 2 * std::max(half_need, half_now + half_now / 2) + 2;
}

// What the session keeps in host memory at most, estimated before it is
// allocated (DESIGN §8, docs/performance.md, "Large sites: past 2^30 cells"):
//  - per cell of the renderer's grid, what the renderer says it keeps in host
//    memory (RendererTraits::host_bytes_per_cell: a host grid's 4-byte
//    floats, cpu_float's 8-byte sums over the cells a call reaches; 0 for a
//    grid on a GPU);
//  - per cell, the finish at the session's downsample ds: the block means and
//    the finished map, 4 bytes a block each (8 / ds^2 a cell; for a grid on a
//    GPU, the pinned copy the map is downloaded into and the map);
//  - per beam, the stored range (4 bytes) and a renderer's per-beam scratch
//    (placement and stripe lists of the CPU backends, the CUDA renderers'
//    pinned staging: 64 bytes at most).
double session_memory_need(const GridGeometry &geo, uint64_t beams, const RendererTraits &traits, double downsample) {
  const double ds = std::max(downsample, 1.0);
  const double per_cell = std::max(traits.host_bytes_per_cell, 0.0) + 8.0 / (ds * ds);
  return per_cell * static_cast<double>(geo.num_cells()) + 68.0 * static_cast<double>(beams);
}

}  // namespace

Mapper::Mapper(const MapperParams &params, const std::string &backend, const BackendOptions &options)
    : params_(params), options_(options) {
  check_options(options);
  renderer_ = first_renderer(backend, options, &auto_choice_);
  params_.validate();
}

Mapper::Mapper(const MapperParams &params, std::unique_ptr<Renderer> renderer, const BackendOptions &options)
    : params_(params), options_(options), renderer_(std::move(renderer)) {
  if (!renderer_) throw Error(ErrorCode::Usage, "Mapper: no renderer");
  check_options(options);
  params_.validate();
}

bool Mapper::choose_renderer(const ScanBatch &scans) {
  if (renderer_) return false;
  AutoChoice c = choose_auto(&scans, params_, options_);
  renderer_ = make_renderer(c.backend, options_);
  auto_choice_ = std::move(c);
  return true;
}

void Mapper::undo_choice() noexcept {
  renderer_.reset();
  auto_choice_.reset();
}

RendererTraits Mapper::backend_traits() const {
  if (renderer_) return renderer_->traits();
  static const RendererTraits host_grid = make_renderer("cpu_threads")->traits();  // auto's fallback
  return host_grid;
}

Mapper::Mapper(const MapperParams &params, const GridGeometry &frame, const std::string &backend,
               const BackendOptions &options)
    : Mapper(params, backend, options) {
  check_fixed_frame(frame, params);
  fixed_frame_ = true;
  geo_ = grid_ = frame;
}

Mapper::Mapper(const MapperParams &params, const GridGeometry &frame, std::unique_ptr<Renderer> renderer,
               const BackendOptions &options)
    : Mapper(params, std::move(renderer), options) {
  check_fixed_frame(frame, params);
  fixed_frame_ = true;
  geo_ = grid_ = frame;
}

GridGeometry Mapper::frame_for(const PoseExtent &extent, const ScanBatch &scans) const {
  if (!fixed_frame_) return size_grid(extent, scans, params_);
  GridGeometry g = geo_;
  if (!g.centre_given) {  // CARMEN's egrid.c: centred on the first scan
    g.x0 = extent.x0;
    g.y0 = extent.y0;
  }
  return g;
}

// The frame an insert grows to: `need` widened by the margin where it fits
// the size limit and the memory budget, else `need` itself.
GridGeometry Mapper::grown_frame(const GridGeometry &need, uint64_t beams) const {
  const int64_t sx = grown_size(need.size_x, grid_.size_x), sy = grown_size(need.size_y, grid_.size_y);
  if (sx > kMaxGridSide || sy > kMaxGridSide) return need;
  GridGeometry g = need;
  g.size_x = static_cast<int>(sx);
  g.size_y = static_cast<int>(sy);
  return fits_memory(g, beams) ? g : need;
}

namespace {

// `bytes` in MiB rounded up or down to `decimals` digits, as a number and as text.
double mebibytes_rounded(double bytes, bool up, int decimals) {
  const double scale = std::pow(10.0, decimals), mib = bytes / (1 << 20) * scale;
  return (up ? std::ceil(mib) : std::floor(mib)) / scale;
}

std::string mebibytes(double bytes, bool up, int decimals = 0) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << mebibytes_rounded(bytes, up, decimals);
  return s.str();
}

// A need above a budget shown with `budget_decimals`, rounded up with as
// many decimals as it takes to read as more than it ("2.1 MiB ... more than
// the budget of 2 MiB"). Compared as numbers, not as text.
std::string need_above(double need, double budget, int budget_decimals) {
  const double shown_budget = mebibytes_rounded(budget, false, budget_decimals);
  int d = 0;
  while (d < 6 && mebibytes_rounded(need, true, d) <= shown_budget) ++d;
  return mebibytes(need, true, d);
}

}  // namespace

double Mapper::memory_need(const GridGeometry &geo, uint64_t beams) const {
  return session_memory_need(geo, beams, backend_traits(), params_.downsample);
}

bool Mapper::fits_memory(const GridGeometry &geo, uint64_t beams) const {
  return options_.max_memory_bytes == 0 || memory_need(geo, beams) <= static_cast<double>(options_.max_memory_bytes);
}

void Mapper::check_memory(const GridGeometry &geo, uint64_t beams) const {
  if (fits_memory(geo, beams)) return;
  const double need = memory_need(geo, beams);
  const uint64_t b = options_.max_memory_bytes;
  const int budget_decimals = b % (1 << 20) == 0 ? 0 : 2;
  const std::string budget = mebibytes(static_cast<double>(b), false, budget_decimals);
  std::ostringstream m;
  const double per_cell = (need - 68.0 * static_cast<double>(beams)) / std::max(1.0, static_cast<double>(geo.num_cells()));
  m << "the map needs about " << need_above(need, static_cast<double>(b), budget_decimals) << " MiB of memory (a grid of "
    << geo.size_x << " x " << geo.size_y << " = " << geo.num_cells() << " cells at " << geo.resolution << " m, "
    << std::setprecision(3) << per_cell << " bytes a cell on " << backend_name() << ", and " << beams
    << " beams), more than the budget of " << budget << " MiB: ";
  if (!options_.budget_hint.empty()) m << "raise it (" << options_.budget_hint << "), or ";
  m << "use a coarser vasco_resolution";
  throw Error(ErrorCode::OutOfMemory, m.str());
}

void Mapper::set_max_memory_bytes(uint64_t bytes) {
  const uint64_t old = options_.max_memory_bytes;
  options_.max_memory_bytes = bytes;
  try {
    if (scans_.num_scans() > 0) check_memory(grid_, scans_.num_beams());
  } catch (...) {
    options_.max_memory_bytes = old;
    throw;
  }
}

void Mapper::start_over(const MapperParams &params) {
  MapperParams p = params;
  p.validate();
  if (fixed_frame_) check_fixed_frame(geo_, p);
  params_ = p;
  scans_ = ScanBatch();
  extent_ = PoseExtent();
  stats_ = MapStats{};
  grid_lost_ = false;
  shift_invariant_ = true;
  if (!fixed_frame_) geo_ = grid_ = GridGeometry();
  if (renderer_) renderer_->forget_scans();  // the next log's beams are not the last one's
}

void Mapper::check_grid_usable(const char *what) const {
  if (scans_.num_scans() == 0) throw Error(ErrorCode::State, std::string(what) + ": no scans inserted");
  if (grid_lost_)
    throw Error(ErrorCode::State, std::string(what) +
                                      ": the grid was lost when a failed call could not restore it; "
                                      "render(poses()) or an insert renders it again");
}

void Mapper::rerender() {
  renderer_->reset(grid_, params_);
  renderer_->apply(scans_, 0, scans_.num_scans(), &stats_);
  ++renders_;
}

// Puts back what `saved` holds (scans_ already truncated to saved.scans) and
// renders the grid again; a render that fails too leaves the grid marked lost.
void Mapper::restore(const Saved &saved) noexcept {
  shift_invariant_ = saved.shift_invariant;
  geo_ = saved.geo;
  grid_ = saved.grid;
  extent_ = saved.extent;
  grid_lost_ = false;
  if (saved.scans > 0) {
    try {
      rerender();
    } catch (...) {
      grid_lost_ = true;
    }
  }
  stats_ = saved.stats;
}

Mapper::InsertPlan Mapper::plan_insert(const ScanBatch &scans) const {
  const size_t before = scans_.num_scans();
  const uint64_t beams = scans_.num_beams() + scans.num_beams();
  InsertPlan plan;
  plan.shift_invariant = shift_invariant_ && beams_shift_invariant(scans, params_);
  plan.extent = extent_;
  for (size_t s = 0; s < scans.num_scans(); ++s) plan.extent.add_pose(scans.x[s], scans.y[s], scans.theta[s], s);
  plan.geo = frame_for(plan.extent, scans);
  const bool fits = before > 0 && plan.geo.size_x <= grid_.size_x && plan.geo.size_y <= grid_.size_y;
  if (before == 0)
    plan.grid = plan.geo;  // the first insert: the PROTOCOL frame itself
  else
    plan.grid = fits ? grid_ : !plan.shift_invariant ? plan.geo : grown_frame(plan.geo, beams);
  plan.full_render = before == 0 || grid_lost_ || !fits;
  check_memory(plan.grid, beams);
  renderer_->check_capacity(beams);
  return plan;
}

void Mapper::apply_insert(const InsertPlan &plan, size_t before) {
  extent_ = plan.extent;
  shift_invariant_ = plan.shift_invariant;
  geo_ = plan.geo;
  grid_ = plan.grid;
  stats_ = MapStats{};
  if (plan.full_render)
    rerender();
  else
    renderer_->apply(scans_, before, scans_.num_scans(), &stats_);
  grid_lost_ = false;
}

void Mapper::insert(const ScanBatch &scans) {
  scans.validate_for_mapping();
  if (scans.num_scans() == 0) return;
  const bool chosen_now = choose_renderer(scans);  // auto, undecided: these scans are the workload
  try {
    const InsertPlan plan = plan_insert(scans);  // throws before anything changes
    const Saved saved = save();
    scans_.append(scans);  // all or nothing
    try {
      apply_insert(plan, saved.scans);
    } catch (...) {
      scans_.truncate(saved.scans);
      restore(saved);
      throw;
    }
  } catch (...) {
    if (chosen_now) undo_choice();
    throw;
  }
}

void Mapper::insert(ScanBatch &&scans) {
  if (scans_.num_scans() > 0) return insert(static_cast<const ScanBatch &>(scans));  // appended: one copy
  scans.validate_for_mapping();
  if (scans.num_scans() == 0) return;
  const bool chosen_now = choose_renderer(scans);
  try {
    const InsertPlan plan = plan_insert(scans);
    const Saved saved = save();
    scans_ = std::move(scans);
    try {
      apply_insert(plan, 0);
    } catch (...) {
      scans = std::move(scans_);
      scans_ = ScanBatch();
      restore(saved);
      throw;
    }
  } catch (...) {
    if (chosen_now) undo_choice();
    throw;
  }
}

void Mapper::render(const std::vector<Pose> &poses) {
  if (poses.size() != scans_.num_scans())
    throw Error(ErrorCode::Usage, "Mapper::render: " + std::to_string(poses.size()) + " poses for " +
                                      std::to_string(scans_.num_scans()) + " stored scans");
  check_poses(poses);
  if (poses.empty()) return;
  PoseExtent extent;
  for (size_t s = 0; s < poses.size(); ++s) extent.add_pose(poses[s].x, poses[s].y, poses[s].theta, s);
  const GridGeometry geo = frame_for(extent, scans_);
  check_memory(geo, scans_.num_beams());
  renderer_->check_capacity(scans_.num_beams());
  std::vector<double> x(poses.size()), y(poses.size()), theta(poses.size());
  for (size_t s = 0; s < poses.size(); ++s) x[s] = poses[s].x, y[s] = poses[s].y, theta[s] = poses[s].theta;
  const Saved saved = save();
  auto swap_poses = [&] {
    x.swap(scans_.x);
    y.swap(scans_.y);
    theta.swap(scans_.theta);
  };
  swap_poses();
  extent_ = extent;
  geo_ = grid_ = geo;
  stats_ = MapStats{};
  try {
    rerender();
    grid_lost_ = false;
  } catch (...) {
    swap_poses();  // the old poses back
    restore(saved);
    throw;
  }
}

bool Mapper::finishes_whole_grid(const char *what, int downsample, int border) const {
  check_grid_usable(what);
  if (downsample < 1) throw Error(ErrorCode::Usage, std::string(what) + ": downsample must be at least 1");
  if (border < 0) throw Error(ErrorCode::Usage, std::string(what) + ": border must not be negative");
  return grid_.size_x == geo_.size_x && grid_.size_y == geo_.size_y;
}

FinishedMap Mapper::finish(int downsample, int border) const {
  if (finishes_whole_grid("Mapper::finish", downsample, border)) return renderer_->finish(downsample, border);
  return renderer_->finish_window(frame_window(), geo_.resolution, downsample, border);  // a grown grid
}

GridWindow Mapper::frame_window() const {
  // frame() lies centred in the grid: the same first scan, whole cells of margin.
  return GridWindow{(grid_.size_x - geo_.size_x) / 2, (grid_.size_y - geo_.size_y) / 2, geo_.size_x, geo_.size_y};
}

FinishedMap Mapper::finish_occupancy(const carmen::OccupancyValues &values, const OccupancyOut &out,
                                     int downsample, int border) const {
  if (finishes_whole_grid("Mapper::finish_occupancy", downsample, border))
    return renderer_->finish_occupancy(downsample, border, values, out);
  return renderer_->finish_occupancy_window(frame_window(), geo_.resolution, downsample, border, values, out);
}

std::vector<float> Mapper::read(const GridWindow &window) const {
  check_grid_usable("Mapper::read");
  check_window(window, geo_);
  const GridWindow frame = frame_window();
  return renderer_->read(GridWindow{window.x0 + frame.x0, window.y0 + frame.y0, window.width, window.height});
}

std::vector<float> Mapper::read() const { return read(GridWindow{0, 0, geo_.size_x, geo_.size_y}); }

std::vector<Pose> Mapper::poses() const {
  std::vector<Pose> p(scans_.num_scans());
  for (size_t s = 0; s < p.size(); ++s) p[s] = {scans_.x[s], scans_.y[s], scans_.theta[s]};
  return p;
}

}  // namespace vasco
