#include "split_renderer.h"

#include <algorithm>
#include <exception>
#include <thread>

#include "carmen_compat/termination_signals.h"
#include "cuda_exact_renderer.h"
#include "cuda_float_renderer.h"

namespace vasco {

std::vector<ColumnBand> split_columns(int size_x, int parts) {
  if (size_x <= 0 || parts <= 1 || size_x > kMaxBandedSide) return {ColumnBand{0, std::max(size_x, 0)}};
  const int64_t units = (static_cast<int64_t>(size_x) + kBandAlign - 1) / kBandAlign;
  const int64_t n = std::min<int64_t>(parts, units);
  std::vector<ColumnBand> bands;
  for (int64_t i = 0; i < n; ++i) {
    const int64_t from = units * i / n * kBandAlign, to = std::min<int64_t>(units * (i + 1) / n * kBandAlign, size_x);
    bands.push_back(ColumnBand{static_cast<int>(from), static_cast<int>(to - from)});
  }
  return bands;
}

namespace {

// The strip a finish gathers at a time: 16 Mi cells (64 MiB of host memory),
// as a grown session's finish reads its window.
constexpr uint64_t kGatherStripCells = uint64_t(16) << 20;

std::unique_ptr<CudaRenderer> make_band_renderer(BackendOptions options, int device) {
  options.cuda_device = device;
  options.split_devices.clear();
  if (options.cuda_mode == CudaMode::Exact) return std::make_unique<CudaExactRenderer>(options, nullptr);
  return std::make_unique<CudaFloatRenderer>(options, nullptr);
}

// Runs body(i) for i in [0, n) on a thread each; rethrows the first failure
// after every thread has ended.
template <class Body>
void on_band_threads(size_t n, Body body) {
  std::vector<std::exception_ptr> failed(n);
  std::vector<std::thread> threads;
  threads.reserve(n);
  try {
    for (size_t i = 0; i < n; ++i)
      threads.push_back(carmen::start_thread([&, i] {
        try {
          body(i);
        } catch (...) {
          failed[i] = std::current_exception();
        }
      }));
  } catch (...) {  // no thread for a band: join those started, then report it
    for (auto &t : threads) t.join();
    throw;
  }
  for (auto &t : threads) t.join();
  for (auto &f : failed)
    if (f) std::rethrow_exception(f);
}

}  // namespace

SplitRenderer::SplitRenderer(const BackendOptions &options, const std::vector<int> &devices) : devices_(devices) {
  if (devices.empty()) throw Error(ErrorCode::Usage, "a split render needs at least one device");
  for (int d : devices) parts_.push_back(make_band_renderer(options, d));
}

SplitRenderer::~SplitRenderer() = default;

void SplitRenderer::require_grid(const char *call) const {
  if (valid_) return;
  throw Error(ErrorCode::State, std::string(call) + " on a split " + name() +
                                    ": no grid (reset first, or again after a failed call)");
}

void SplitRenderer::reset(const GridGeometry &geo, const MapperParams &params) {
  valid_ = false;
  const std::vector<ColumnBand> bands = split_columns(geo.size_x, static_cast<int>(parts_.size()));
  for (size_t i = 0; i < bands.size(); ++i) parts_[i]->reset_band(geo, params, bands[i]);
  bands_ = bands;
  geo_ = geo;
  valid_ = true;
}

void SplitRenderer::apply(const ScanBatch &scans, size_t first, size_t last, MapStats *stats) {
  require_grid("apply");
  std::vector<MapStats> st(bands_.size());
  valid_ = false;  // until every band has applied the scans
  try {
    on_band_threads(bands_.size(), [&](size_t i) { parts_[i]->apply(scans, first, last, &st[i]); });
  } catch (...) {
    // A band that succeeded keeps the scans' ranges (float mode's device
    // copy) as sent, though the caller takes the scans back: every band
    // sends them all again next time.
    forget_scans();
    throw;
  }
  valid_ = true;
  // Every band sees every beam; each updates its own cells; they run at once.
  MapStats sum = st[0];
  for (size_t i = 1; i < st.size(); ++i) {
    sum.cell_updates += st[i].cell_updates;
    sum.prep_s = std::max(sum.prep_s, st[i].prep_s);
    sum.upload_s = std::max(sum.upload_s, st[i].upload_s);
    sum.map_s = std::max(sum.map_s, st[i].map_s);
    sum.download_s = std::max(sum.download_s, st[i].download_s);
  }
  if (stats != nullptr) *stats = sum;
}

void SplitRenderer::gather(const GridWindow &w, std::vector<float> *out) {
  const size_t rows = static_cast<size_t>(w.height);
  out->resize(static_cast<size_t>(w.width) * rows);
  for (size_t i = 0; i < bands_.size(); ++i) {
    const int64_t from = std::max<int64_t>(w.x0, bands_[i].x0);
    const int64_t to = std::min<int64_t>(static_cast<int64_t>(w.x0) + w.width,
                                         static_cast<int64_t>(bands_[i].x0) + bands_[i].width);
    if (from >= to) continue;
    const std::vector<float> part = parts_[i]->read(
        GridWindow{static_cast<int>(from - bands_[i].x0), w.y0, static_cast<int>(to - from), w.height});
    std::copy(part.begin(), part.end(), out->begin() + static_cast<size_t>(from - w.x0) * rows);
  }
}

// Where every band but the last is whole blocks wide (downsample divides
// kBandAlign: 1, 2, 4, ...), each band finishes its own blocks on its device
// and only the finished map comes back: the known boxes are joined, the crop
// taken from the frame's blocks, and each band sends the crop's block
// columns it holds. The blocks are the frame's: a band's first column is a
// multiple of the downsample, and the last band's remainder is the frame's.
// Other downsamples gather the grid to the host a strip at a time.
FinishedMap SplitRenderer::finish(int downsample, int border) {
  finish::check_arguments(downsample, border);
  require_grid("finish");
  if (kBandAlign % downsample != 0) return finish_on_host(downsample, border);
  std::vector<finish::KnownBox> known(bands_.size());
  on_band_threads(bands_.size(), [&](size_t i) { known[i] = parts_[i]->finish_blocks(downsample); });
  finish::KnownBox all;
  for (size_t i = 0; i < bands_.size(); ++i) {
    if (known[i].max_x < 0) continue;  // no known block in the band
    const int first = bands_[i].x0 / downsample;
    finish::widen(all, known[i].min_x + first, known[i].min_y);
    finish::widen(all, known[i].max_x + first, known[i].max_y);
  }
  const finish::Blocks blocks = finish::blocks_of(geo_.size_x, geo_.size_y, downsample);
  const finish::Crop crop = finish::crop_of(all, blocks, border);
  FinishedMap m = finish::finished_frame(crop, geo_.resolution, downsample);
  m.cells.resize(static_cast<size_t>(crop.count()));
  on_band_threads(bands_.size(), [&](size_t i) {
    const int first = bands_[i].x0 / downsample, count = bands_[i].width / downsample;
    const int from = std::max(crop.min_x, first), to = std::min(crop.min_x + crop.size_x, first + count);
    if (from >= to || crop.size_y == 0) return;
    finish::Crop part = crop;
    part.min_x = from - first;
    part.size_x = to - from;
    const std::vector<float> cells = parts_[i]->read_blocks(part);
    std::copy(cells.begin(), cells.end(), m.cells.begin() + static_cast<size_t>(from - crop.min_x) * crop.size_y);
  });
  return m;
}

FinishedMap SplitRenderer::finish_on_host(int downsample, int border) {
  std::vector<float> strip;
  const ColumnStrip columns = [&](int x0, int width) {
    gather(GridWindow{x0, 0, width, geo_.size_y}, &strip);
    return strip.data();
  };
  return finish_grid_by_columns(columns, geo_.size_x, geo_.size_y, geo_.resolution, downsample, border,
                                kGatherStripCells);
}

std::vector<float> SplitRenderer::read(const GridWindow &w) {
  require_grid("read");
  std::vector<float> out;
  gather(w, &out);
  return out;
}

void SplitRenderer::forget_scans() {
  for (auto &p : parts_) p->forget_scans();
}

std::unique_ptr<Renderer> make_split_renderer(const BackendOptions &options) {
  for (int d : options.split_devices) {
    std::string why;
    if (!cuda_usable(d, &why)) throw Error(ErrorCode::NoGpu, "no usable GPU for a split render: " + why);
  }
  return std::make_unique<SplitRenderer>(options, options.split_devices);
}

}  // namespace vasco
