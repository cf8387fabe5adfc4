// renderer.h's free functions and the Renderer's default finishes (of the
// grid as occupancy data, of a window of it).
#include "vasco_gpu/renderer.h"

#include <utility>

#include "carmen_compat/occupancy_grid.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/grid.h"

namespace vasco {

FinishedMap Renderer::finish_occupancy(int downsample, int border, const carmen::OccupancyValues &values,
                                       const OccupancyOut &out) {
  return occupancy_of(finish(downsample, border), values, out);
}

namespace {

// Cells a strip of a window's finish reads at a time (finish_grid_by_columns):
// 64 MiB of floats, or one block column when that is more.
constexpr uint64_t kFinishStripCells = uint64_t(16) << 20;

}  // namespace

FinishedMap Renderer::finish_window(const GridWindow &window, double resolution, int downsample, int border) {
  std::vector<float> strip;
  const ColumnStrip columns = [&](int x0, int width) {
    strip = read(GridWindow{window.x0 + x0, window.y0, width, window.height});
    return strip.data();
  };
  return finish_grid_by_columns(columns, window.width, window.height, resolution, downsample, border,
                                kFinishStripCells);
}

FinishedMap Renderer::finish_occupancy_window(const GridWindow &window, double resolution, int downsample,
                                              int border, const carmen::OccupancyValues &values,
                                              const OccupancyOut &out) {
  return occupancy_of(finish_window(window, resolution, downsample, border), values, out);
}

FinishedMap occupancy_of(FinishedMap map, const carmen::OccupancyValues &values, const OccupancyOut &out) {
  const size_t n = map.cells.size();
  if (n != static_cast<size_t>(map.size_x) * static_cast<size_t>(map.size_y))
    throw Error(ErrorCode::Internal, "a finished map whose cells disagree with its size (a bug)");
  int8_t *data = out(n);
  if (n > 0) carmen::occupancy_grid_data(map.cells.data(), map.size_x, map.size_y, values, data);
  map.cells = std::vector<float>();
  return map;
}

std::vector<float> render_grid(Renderer &renderer, const ScanBatch &scans, const MapperParams &params,
                               const GridGeometry &geo, MapStats *stats) {
  renderer.reset(geo, params);
  renderer.apply(scans, 0, scans.num_scans(), stats);
  return renderer.read(GridWindow{0, 0, geo.size_x, geo.size_y});
}

}  // namespace vasco
