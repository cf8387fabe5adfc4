#include "vasco_gpu/mapper.hpp"

#include <chrono>
#include <sstream>
#include <stdexcept>
#include <string>

namespace vasco {
namespace {

void check_window(const GridWindow &w, const GridGeometry &geo) {
  if (w.width < 0 || w.height < 0 || w.x0 < 0 || w.y0 < 0 ||
      static_cast<long>(w.x0) + w.width > geo.size_x || static_cast<long>(w.y0) + w.height > geo.size_y)
    throw std::invalid_argument("Mapper::read: window [" + std::to_string(w.x0) + ", +" +
                                std::to_string(w.width) + ") x [" + std::to_string(w.y0) + ", +" +
                                std::to_string(w.height) + ") is not inside the " +
                                std::to_string(geo.size_x) + " x " + std::to_string(geo.size_y) + " grid");
}

}  // namespace

Mapper::Mapper(const MapperParams &params, const std::string &backend, const BackendOptions &options)
    : params_(params), options_(options), renderer_(make_renderer(backend, options)) {
  params_.validate();
}

Mapper::Mapper(const MapperParams &params, const GridGeometry &frame, const std::string &backend,
               const BackendOptions &options)
    : Mapper(params, backend, options) {
  if (frame.size_x <= 0 || frame.size_y <= 0 || frame.num_cells() > kMaxGridCells)
    throw std::invalid_argument("Mapper: a fixed frame needs a size between 1 and " +
                                std::to_string(kMaxGridCells) + " cells");
  if (frame.resolution != params.resolution)
    throw std::invalid_argument("Mapper: the frame's resolution differs from vasco_resolution");
  fixed_frame_ = true;
  geo_ = frame;
}

GridGeometry Mapper::frame_for(const PoseExtent &extent, const ScanBatch &scans) const {
  if (!fixed_frame_) return size_grid(extent, scans, params_);
  GridGeometry g = geo_;
  g.x0 = extent.x0;
  g.y0 = extent.y0;
  return g;
}

// What the session keeps in host memory, estimated before it is allocated:
// the grid (4 bytes a cell; CPU renderers), the stored scans (4 bytes a beam)
// and a renderer's per-beam scratch (placement and stripe lists of the CPU
// backends, the CUDA renderer's pinned staging: 64 bytes a beam at most).
void Mapper::check_memory(const GridGeometry &geo, uint64_t beams) const {
  if (options_.max_memory_bytes == 0) return;
  const bool device_grid = renderer_->traits().grid_on_device;
  const double need = (device_grid ? 0.0 : 4.0 * static_cast<double>(geo.num_cells())) + 68.0 * beams;
  if (need <= static_cast<double>(options_.max_memory_bytes)) return;
  std::ostringstream m;
  m << "the map needs about " << static_cast<uint64_t>(need / (1 << 20)) << " MiB of memory (a grid of "
    << geo.size_x << " x " << geo.size_y << " cells at " << geo.resolution << " m and " << beams
    << " beams), more than the budget of " << (options_.max_memory_bytes >> 20)
    << " MiB: raise it (log2map --max-memory MiB), or use a coarser vasco_resolution";
  throw std::runtime_error(m.str());
}

void Mapper::rerender() {
  renderer_->reset(geo_, params_);
  renderer_->apply(scans_, 0, scans_.num_scans(), &stats_);
  ++renders_;
}

void Mapper::insert(const ScanBatch &scans) {
  if (scans.num_scans() == 0) return;
  PoseExtent extent = extent_;
  extent.add(scans, 0, scans.num_scans());
  const GridGeometry geo = frame_for(extent, scans);  // throws before anything changes
  check_memory(geo, scans_.num_beams() + scans.num_beams());
  renderer_->check_capacity(scans_.num_beams() + scans.num_beams());
  const size_t before = scans_.num_scans();
  for (size_t s = 0; s < scans.num_scans(); ++s)
    scans_.add_scan(scans.x[s], scans.y[s], scans.theta[s], scans.first_angle[s], scans.angle_step[s],
                    scans.ranges_of(s), scans.beams_in(s), scans.line[s]);
  extent_ = extent;
  stats_ = MapStats{};
  const bool same_frame = before > 0 && geo.size_x == geo_.size_x && geo.size_y == geo_.size_y;
  geo_ = geo;
  if (!same_frame) {
    rerender();
    return;
  }
  renderer_->apply(scans_, before, scans_.num_scans(), &stats_);
}

void Mapper::render(const std::vector<Pose> &poses) {
  if (poses.size() != scans_.num_scans())
    throw std::invalid_argument("Mapper::render: " + std::to_string(poses.size()) + " poses for " +
                                std::to_string(scans_.num_scans()) + " stored scans");
  if (poses.empty()) return;
  std::vector<double> x(poses.size()), y(poses.size()), theta(poses.size());
  for (size_t s = 0; s < poses.size(); ++s) {
    x[s] = poses[s].x;
    y[s] = poses[s].y;
    theta[s] = poses[s].theta;
  }
  x.swap(scans_.x);
  y.swap(scans_.y);
  theta.swap(scans_.theta);
  PoseExtent extent;
  extent.add(scans_, 0, scans_.num_scans());
  GridGeometry geo;
  try {
    geo = frame_for(extent, scans_);
    check_memory(geo, scans_.num_beams());
    renderer_->check_capacity(scans_.num_beams());
  } catch (...) {  // the old poses stay
    x.swap(scans_.x);
    y.swap(scans_.y);
    theta.swap(scans_.theta);
    throw;
  }
  extent_ = extent;
  geo_ = geo;
  stats_ = MapStats{};
  rerender();
}

FinishedMap Mapper::finish(int downsample, int border) const {
  if (scans_.num_scans() == 0) throw std::logic_error("Mapper::finish: no scans inserted");
  return renderer_->finish(downsample, border);
}

std::vector<float> Mapper::read(const GridWindow &window) const {
  if (scans_.num_scans() == 0) throw std::logic_error("Mapper::read: no scans inserted");
  check_window(window, geo_);
  return renderer_->read(window);
}

std::vector<float> Mapper::read() const { return read(GridWindow{0, 0, geo_.size_x, geo_.size_y}); }

std::vector<Pose> Mapper::poses() const {
  std::vector<Pose> p(scans_.num_scans());
  for (size_t s = 0; s < p.size(); ++s) p[s] = {scans_.x[s], scans_.y[s], scans_.theta[s]};
  return p;
}

}  // namespace vasco
