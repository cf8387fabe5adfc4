// The CUDA renderer of a mapping session: the evidence grid, the scans'
// ranges (float mode) and every scratch buffer stay on the GPU between calls,
// grown to a high-water mark and then reused; one stream per renderer.
//   insert  (apply of new scans): float mode uploads their ranges once and a
//           32-byte record per scan; exact mode places their beams on the host
//           with the oracle's own code (DESIGN §2.2) and uploads 16 bytes per
//           beam, then continues the grid in (scan, beam) order.
//   render  (reset + apply of every scan): float mode uploads the per-scan
//           records only (the poses, placed); the ranges are already there.
//   finish  CARMEN's finish on the device; only the finished map comes back,
//           into pinned memory.
#include "cuda_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <functional>

#include "cuda_check.h"
#include "cuda_host_support.h"
#include "egrid_kernels.h"
#include "vasco_gpu/beam_placement.h"
#include "vasco_gpu/oracle.h"
#include "vasco_gpu/parallel.h"

namespace vasco {

using cuda_host::check_fits;
using cuda_host::reserve;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }


// Tiles a beam's walk can enter, at most: the walk is monotone in x and y and
// moves at most one cell per step along each axis, so up to step k_max =
// table_size - 1 it stays in a box of that half-width, and it enters a new
// tile only by crossing a tile boundary. For a closed-form line the box is
// also bounded by the end cell. Degenerate lines (egrid_math.h) get the box
// bound alone, whatever their direction.
uint64_t tile_bound_of_beam(const oracle::ScanStart &s, const PlacedBeam &b, int table_size) {
  if (table_size <= 0) return 0;
  const int64_t reach = table_size - 1, tile = cuda::kTile;
  if (!egrid::is_closed_form_line(s.x1, s.y1, b.x2, b.y2)) return 2 * (static_cast<uint64_t>(reach) / tile + 1) + 1;
  auto tiles_crossed = [&](int64_t from, int64_t to) {
    const int64_t end = from + std::max(-reach, std::min(reach, to - from));
    auto floor_div = [&](int64_t v) { return v >= 0 ? v / tile : -((-v + tile - 1) / tile); };
    return static_cast<uint64_t>(std::llabs(floor_div(end) - floor_div(from)));
  };
  return 1 + tiles_crossed(s.x1, b.x2) + tiles_crossed(s.y1, b.y2);
}

// The sum of tile_bound_of_beam over a placed batch, on all cores.
uint64_t exact_pair_bound(const PlacedBeam *beams, size_t n, const std::vector<oracle::ScanStart> &starts,
                          int table_size) {
  const int nt = n < (size_t(1) << 16) ? 1 : hardware_threads();
  std::vector<uint64_t> part(static_cast<size_t>(nt), 0);
  run_on_threads(nt, [&](int t) {
    const size_t a = n * t / nt, b = n * (t + 1) / nt;
    uint64_t sum = 0;
    for (size_t i = a; i < b; ++i) sum += tile_bound_of_beam(starts[beams[i].scan], beams[i], table_size);
    part[static_cast<size_t>(t)] = sum;
  });
  uint64_t total = 0;
  for (uint64_t p : part) total += p;
  return total;
}

// VASCO_CUDA_NO_TABLES=1 computes every update in full, as grids too large
// for the tables are: the tests compare both ways bit for bit.
bool tables_disabled() {
  const char *v = std::getenv("VASCO_CUDA_NO_TABLES");
  return v != nullptr && *v != '\0' && std::string(v) != "0";
}

}  // namespace

CudaRenderer::CudaRenderer(const BackendOptions &options) : options_(options) {
  VG_CUDA_CHECK(cudaSetDevice(options.cuda_device));
  stream_ = std::make_unique<cuda::Stream>();
  e_start_ = std::make_unique<cuda::Event>();
  e_uploaded_ = std::make_unique<cuda::Event>();
  e_mapped_ = std::make_unique<cuda::Event>();
}

CudaRenderer::~CudaRenderer() = default;

std::string CudaRenderer::name() const { return exact() ? "cuda_exact" : "cuda_float"; }

void CudaRenderer::reset(const GridGeometry &geo, const MapperParams &params) {
  VG_CUDA_CHECK(cudaSetDevice(options_.cuda_device));
  geo_ = geo;
  params_ = params;
  const size_t cells = geo.num_cells();
  if (exact()) {
    if (cells > grid_.size()) check_fits((cells - grid_.size()) * sizeof(float), "the evidence grid");
    reserve(grid_, cells);
    cuda::launch_fill(grid_.get(), cells, egrid::kUnknown, stream_->get());
    build_tables();
  } else {
    if (cells > sums_.size())
      check_fits((cells - sums_.size()) * sizeof(unsigned long long), "the evidence grid");
    reserve(sums_, cells);
    cuda::launch_float_clear(sums_.get(), cells, stream_->get());
    float_beams_ = 0;
    fixed_base_ = 0;
  }
}

// Float mode: refuses a grid whose beams could carry a cell's fixed-point
// sum past kFixedLimit (egrid_kernels.h): a cell takes one update per beam at
// most, of at most `step` log-odds. vasco's defaults allow 2 x 10^7 beams,
// far beyond any log.
void CudaRenderer::check_capacity(uint64_t beams) const {
  if (exact()) return;
  auto logit = [](double p) { return std::log(p / (1 - p)); };
  const double step = std::max(std::fabs(logit(params_.p_occ) - logit(params_.p_prior)),
                               std::fabs(logit(params_.p_emp) - logit(params_.p_prior)));
  if (fixed_base_ + static_cast<double>(beams) * step > cuda::kFixedLimit)
    throw std::runtime_error("cuda float mode: " + std::to_string(beams) +
                             " beams could push a cell's log-odds past the fixed-point range (+-2^22); "
                             "use the exact mode or a CPU backend for this log");
}

cuda::GridCells CudaRenderer::cells() const {
  cuda::GridCells c;
  if (exact()) {
    c.probs = grid_.get();
  } else {
    c.sums = sums_.get();
    c.logodds_prior = kernel_model_of<float>(params_, geo_).logodds_prior;
  }
  return c;
}

// The exact mode's distance and odds-factor tables, built once per
// parameter set (they replace a sqrt and two divisions per update).
void CudaRenderer::build_tables() {
  const int T = params_.table_size();
  const size_t t2 = static_cast<size_t>(std::max(T, 0)) * static_cast<size_t>(std::max(T, 0));
  use_tables_ = T > 0 && T <= cuda::kMaxExactTable && !tables_disabled();
  if (!use_tables_ || tables_key_ == params_.table_key()) return;
  reserve(factors_, t2);
  reserve(reach_, static_cast<size_t>(T));
  cuda::launch_exact_tables(kernel_model_of<double>(params_, geo_), factors_.get(), reach_.get(), stream_->get());
  tables_key_ = params_.table_key();
}

// Float mode's increment tables for the current parameters (built when they
// change), or null when they would be too large.
const int2 *CudaRenderer::float_tables() {
  const int T = params_.table_size();
  if (T <= 0 || T > cuda::kMaxFloatTable || tables_disabled()) return nullptr;
  if (float_tables_key_ != params_.table_key()) {
    reserve(increments_, static_cast<size_t>(T) * static_cast<size_t>(T));
    cuda::launch_float_tables(kernel_model_of<float>(params_, geo_), increments_.get(), stream_->get());
    float_tables_key_ = params_.table_key();
  }
  return increments_.get();
}

void CudaRenderer::apply(const ScanBatch &scans, size_t first, size_t last, MapStats *stats) {
  VG_CUDA_CHECK(cudaSetDevice(options_.cuda_device));
  last = std::min(last, scans.num_scans());
  first = std::min(first, last);
  MapStats st;
  st.scans = last - first;
  if (exact()) {
    // (tile, beam) pairs are counted in 32 bits: a run of scans that could
    // pass 2^32 of them goes in several launches, each continuing the grid.
    const uint64_t max_beams = exact_beams_per_launch();
    for (size_t a = first; a < last;) {
      size_t b = a + 1;
      while (b < last && scans.beam_offset[b + 1] - scans.beam_offset[a] <= max_beams) ++b;
      apply_exact(scans, a, b, &st);
      a = b;
    }
  } else if (last > first) {
    apply_float(scans, first, last, &st);
  }
  if (stats != nullptr) *stats = st;
}

// Beams per exact-mode launch such that the pairs, at most 2 * (table_size /
// kTile + 2) per beam (a monotone walk of table_size cells enters no more
// tiles), stay below 2^32.
uint64_t CudaRenderer::exact_beams_per_launch() const {
  const uint64_t per_beam = 2 * (static_cast<uint64_t>(std::max(params_.table_size(), 0)) / cuda::kTile + 2);
  return std::max<uint64_t>(1, (uint64_t(UINT32_MAX) - 1) / per_beam);
}

// Float mode's device copy of the scans' ranges, append-only: scans already
// there are not sent again (a render sends none).
void CudaRenderer::upload_ranges(const ScanBatch &scans, size_t last) {
  const uint64_t need = scans.beam_offset[last];
  if (need <= stored_beams_) return;
  if (need > ranges_.size()) {
    const size_t grown = std::max<size_t>(need, ranges_.size() + ranges_.size() / 2);
    check_fits((grown - ranges_.size()) * sizeof(float), "the scans' ranges");
    cuda::DeviceBuffer<float> bigger(grown);
    if (stored_beams_)
      VG_CUDA_CHECK(cudaMemcpyAsync(bigger.get(), ranges_.get(), stored_beams_ * sizeof(float),
                                    cudaMemcpyDeviceToDevice, stream_->get()));
    VG_CUDA_CHECK(cudaStreamSynchronize(stream_->get()));  // the old buffer is freed next
    ranges_ = std::move(bigger);
  }
  const size_t n = need - stored_beams_;
  reserve(staging_ranges_, n);  // free: every call ends with the stream idle
  std::memcpy(staging_ranges_.get(), scans.range.data() + stored_beams_, n * sizeof(float));
  VG_CUDA_CHECK(cudaMemcpyAsync(ranges_.get() + stored_beams_, staging_ranges_.get(), n * sizeof(float),
                                cudaMemcpyHostToDevice, stream_->get()));
  stored_beams_ = need;
}

void CudaRenderer::apply_float(const ScanBatch &scans, size_t first, size_t last, MapStats *st) {
  const auto t_prep = Clock::now();
  if (scans.beam_offset[last] > UINT32_MAX)
    throw std::runtime_error("cuda float mode: more than 2^32 beams stored");
  check_capacity(float_beams_ + (scans.beam_offset[last] - scans.beam_offset[first]));  // before any update
  float_beams_ += scans.beam_offset[last] - scans.beam_offset[first];
  upload_ranges(scans, last);
  // Scan records of [first, last), placed with scan 0 fixing the start pose.
  oracle::GridFrame frame;
  frame.size_x = geo_.size_x;
  frame.size_y = geo_.size_y;
  frame.resolution = geo_.resolution;
  frame.theta_offset = geo_.theta_offset;
  oracle::scan_start(frame, scans.x[0], scans.y[0], scans.theta[0]);
  const size_t n = last - first;
  reserve(staging_scans_, n);
  for (size_t s = first; s < last; ++s) {
    const oracle::ScanStart p = oracle::scan_start(frame, scans.x[s], scans.y[s], scans.theta[s]);
    cuda::FloatScan &f = staging_scans_[s - first];
    f.lx = static_cast<float>(p.lx);
    f.ly = static_cast<float>(p.ly);
    f.theta = static_cast<float>(p.theta);
    f.x1 = p.x1;
    f.y1 = p.y1;
    f.first = static_cast<float>(scans.first_angle[s]);
    f.step = static_cast<float>(scans.angle_step[s]);
    f.beam_begin = static_cast<uint32_t>(scans.beam_offset[s]);
    f.beam_count = scans.beams_in(s);
  }
  reserve(scan_records_, n);
  reserve(counters_, 3);
  st->prep_s += seconds_since(t_prep);
  cuda::Event &e0 = *e_start_, &e_up = *e_uploaded_, &e_map = *e_mapped_;
  e0.record(stream_->get());
  VG_CUDA_CHECK(cudaMemcpyAsync(scan_records_.get(), staging_scans_.get(), n * sizeof(cuda::FloatScan),
                                cudaMemcpyHostToDevice, stream_->get()));
  VG_CUDA_CHECK(cudaMemsetAsync(counters_.get(), 0, 3 * sizeof(unsigned long long), stream_->get()));
  e_up.record(stream_->get());
  cuda::launch_float_map(kernel_model_of<float>(params_, geo_), float_tables(), scan_records_.get(),
                         static_cast<int>(n), ranges_.get(), sums_.get(), counters_.get(), stream_->get());
  e_map.record(stream_->get());
  reserve(staging_counters_, 3);
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_counters_.get(), counters_.get(), 3 * sizeof(unsigned long long),
                                cudaMemcpyDeviceToHost, stream_->get()));
  VG_CUDA_CHECK(cudaStreamSynchronize(stream_->get()));  // the call's result is complete
  st->beams_used += staging_counters_[0];
  st->beams_skipped += staging_counters_[1];
  st->cell_updates += staging_counters_[2];
  st->upload_s += e_up.since(e0) / 1e3;
  st->map_s += e_map.since(e_up) / 1e3;
}

// Exact mode, in three parts: place the beams on the host into pinned
// staging; upload and list (tile, beam) pairs; apply them tile by tile. No
// wait between the parts: the pair arrays are sized by a host bound.
void CudaRenderer::apply_exact(const ScanBatch &scans, size_t first, size_t last, MapStats *st) {
  const auto t_prep = Clock::now();
  const uint64_t pair_bound = place_exact_beams(scans, first, last, st);
  st->prep_s += seconds_since(t_prep);
  if (exact_beams_ == 0) return;
  launch_exact_apply(pair_bound, st);
}

// Places the beams of scans [first, last) with the oracle's code, on every
// core, straight into the pinned staging buffer; returns the bound on their
// (tile, beam) pairs.
uint64_t CudaRenderer::place_exact_beams(const ScanBatch &scans, size_t first, size_t last, MapStats *st) {
  const BeamLayout layout = lay_out_beams(scans, geo_, 0, first, last);
  exact_beams_ = layout.used();
  exact_scans_ = layout.starts.size();
  st->beams_used += exact_beams_;
  st->beams_skipped += layout.skipped;
  VG_CUDA_CHECK(cudaStreamSynchronize(stream_->get()));  // staging is free (every call ends idle)
  reserve(staging_beams_, std::max<uint64_t>(exact_beams_, 1));
  reserve(staging_starts_, std::max<size_t>(exact_scans_, 1));
  PlacedBeam *beams = staging_beams_.get();
  place_laid_out_beams(scans, geo_, params_, layout, 0, beams);
  for (size_t s = 0; s < exact_scans_; ++s) staging_starts_[s] = {layout.starts[s].x1, layout.starts[s].y1};
  return exact_pair_bound(beams, exact_beams_, layout.starts, params_.table_size());
}

void CudaRenderer::reserve_exact_scratch(uint64_t pair_bound, size_t tiles) {
  const size_t nb = exact_beams_, ns = exact_scans_;
  reserve(beams_, nb);
  reserve(starts_, ns);
  reserve(lines_, nb);
  reserve(counts_, nb + 1);
  reserve(offsets_, nb + 1);
  for (auto *b : {&tile_begin_, &tile_end_, &order_, &order_keys_, &order_keys_out_, &order_ids_}) reserve(*b, tiles);
  reserve(scan_tmp_, std::max<size_t>(cuda::exact_scan_temp_bytes(nb), 1));
  reserve(order_tmp_, std::max<size_t>(cuda::exact_order_temp_bytes(tiles), 1));
  reserve(updates_, 2);
  const size_t pairs = std::max<size_t>(pair_bound, 1);
  if (pairs > pair_tile_.size())
    check_fits(4 * (pairs - pair_tile_.size()) * sizeof(uint32_t), "exact mode (tile lists)");
  for (auto *b : {&pair_tile_, &pair_beam_, &sorted_tile_, &sorted_beam_}) reserve(*b, pairs);
  reserve(sort_tmp_, std::max<size_t>(cuda::exact_sort_temp_bytes(pairs), 1));
}

void CudaRenderer::launch_exact_apply(uint64_t pair_bound, MapStats *st) {
  const size_t nb = exact_beams_, ns = exact_scans_;
  const cuda::KernelModel<double> m = kernel_model_of<double>(params_, geo_);
  const size_t tiles = static_cast<size_t>((geo_.size_x + cuda::kTile - 1) / cuda::kTile) *
                       ((geo_.size_y + cuda::kTile - 1) / cuda::kTile);
  reserve_exact_scratch(pair_bound, tiles);
  cuda::Event &e0 = *e_start_, &e_up = *e_uploaded_, &e_map = *e_mapped_;
  cudaStream_t s = stream_->get();
  e0.record(s);
  VG_CUDA_CHECK(cudaMemcpyAsync(beams_.get(), staging_beams_.get(), nb * sizeof(PlacedBeam),
                                cudaMemcpyHostToDevice, s));
  VG_CUDA_CHECK(cudaMemcpyAsync(starts_.get(), staging_starts_.get(), ns * sizeof(cuda::StartCell),
                                cudaMemcpyHostToDevice, s));
  e_up.record(s);
  cuda_host::StageTimer timer(s);
  timer.mark("start");
  VG_CUDA_CHECK(cudaMemsetAsync(updates_.get(), 0, 2 * sizeof(unsigned long long), s));
  VG_CUDA_CHECK(cudaMemsetAsync(counts_.get(), 0, (nb + 1) * sizeof(uint32_t), s));
  cuda::launch_exact_lines(m, beams_.get(), starts_.get(), nb, lines_.get(), counts_.get(), s);
  timer.mark("lines");
  cuda::exact_scan(counts_.get(), offsets_.get(), nb, scan_tmp_.get(), scan_tmp_.size(), s);
  timer.mark("scan");
  cuda::launch_exact_pairs(m, lines_.get(), offsets_.get(), nb, pair_bound, pair_tile_.get(), pair_beam_.get(),
                           updates_.get() + 1, s);
  timer.mark("pairs");
  // kNoTile's low tile_bits bits must not name a tile: 2^tile_bits > tiles.
  int tile_bits = 1;
  while ((size_t(1) << tile_bits) <= tiles) ++tile_bits;
  if (pair_bound)
    cuda::exact_sort(pair_tile_.get(), sorted_tile_.get(), pair_beam_.get(), sorted_beam_.get(), pair_bound,
                     tile_bits, sort_tmp_.get(), sort_tmp_.size(), s);
  timer.mark("sort");
  cuda::launch_exact_tile_ranges(sorted_tile_.get(), pair_bound, tile_begin_.get(), tile_end_.get(), tiles, s);
  cuda::exact_tile_order(tile_begin_.get(), tile_end_.get(), tiles, order_.get(), order_keys_.get(),
                         order_keys_out_.get(), order_ids_.get(), order_tmp_.get(), order_tmp_.size(), s);
  timer.mark("tile order");
  cuda::launch_exact_tiles(m, lines_.get(), sorted_beam_.get(), order_.get(), tile_begin_.get(), tile_end_.get(),
                           use_tables_ ? factors_.get() : nullptr, use_tables_ ? reach_.get() : nullptr,
                           grid_.get(), updates_.get(), s);
  timer.mark("tiles");
  e_map.record(s);
  reserve(staging_counters_, 2);
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_counters_.get(), updates_.get(), 2 * sizeof(unsigned long long),
                                cudaMemcpyDeviceToHost, s));
  VG_CUDA_CHECK(cudaStreamSynchronize(s));  // the call's result is complete
  if (staging_counters_[1] != 0)
    throw std::logic_error("cuda exact mode: more (tile, beam) pairs than the host's bound (a bug)");
  timer.report();
  if (std::getenv("VASCO_CUDA_PROFILE")) report_tile_lists(pair_bound, tiles);
  st->cell_updates += staging_counters_[0];
  st->upload_s += e_up.since(e0) / 1e3;
  st->map_s += e_map.since(e_up) / 1e3;
}

// Profiling only (VASCO_CUDA_PROFILE): the pairs and the longest tile
// lists, which bound the tile kernel (a tile's list runs in order).
void CudaRenderer::report_tile_lists(uint64_t pair_bound, size_t tiles) {
  std::vector<uint32_t> begin(tiles), end(tiles), order(std::min<size_t>(tiles, 4));
  VG_CUDA_CHECK(cudaMemcpy(begin.data(), tile_begin_.get(), tiles * 4, cudaMemcpyDeviceToHost));
  VG_CUDA_CHECK(cudaMemcpy(end.data(), tile_end_.get(), tiles * 4, cudaMemcpyDeviceToHost));
  uint64_t pairs = 0;
  std::vector<uint32_t> len(tiles);
  for (size_t t = 0; t < tiles; ++t) pairs += len[t] = end[t] - begin[t];
  std::sort(len.begin(), len.end(), std::greater<uint32_t>());
  std::fprintf(stderr, "  [cuda] beams %llu, pairs %llu (bound %llu), tiles %zu, longest lists %u %u %u %u\n",
               static_cast<unsigned long long>(exact_beams_), static_cast<unsigned long long>(pairs),
               static_cast<unsigned long long>(pair_bound), tiles, len.size() > 0 ? len[0] : 0,
               len.size() > 1 ? len[1] : 0, len.size() > 2 ? len[2] : 0, len.size() > 3 ? len[3] : 0);
}

FinishedMap CudaRenderer::finish(int downsample, int border) {
  if (downsample < 1) throw std::invalid_argument("downsample must be at least 1");
  if (border < 0) throw std::invalid_argument("border must not be negative");
  const int ds = downsample, nx = geo_.size_x / ds, ny = geo_.size_y / ds;
  cudaStream_t s = stream_->get();
  reserve(blocks_, std::max<size_t>(static_cast<size_t>(nx) * ny, 1));
  reserve(bbox_, 4);
  reserve(staging_bbox_, 4);
  VG_CUDA_CHECK(cudaStreamSynchronize(s));
  // CARMEN's start values; every known block widens them.
  staging_bbox_[0] = nx - border - 1;
  staging_bbox_[1] = border;
  staging_bbox_[2] = ny - border - 1;
  staging_bbox_[3] = border;
  VG_CUDA_CHECK(cudaMemcpyAsync(bbox_.get(), staging_bbox_.get(), 4 * sizeof(int), cudaMemcpyHostToDevice, s));
  cuda::launch_finish_blocks(cells(), geo_.size_x, geo_.size_y, ds, blocks_.get(), bbox_.get(), s);
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_bbox_.get(), bbox_.get(), 4 * sizeof(int), cudaMemcpyDeviceToHost, s));
  VG_CUDA_CHECK(cudaStreamSynchronize(s));
  const int min_x = std::max(staging_bbox_[0] - border, 0), max_x = std::min(staging_bbox_[1] + border, nx - 1);
  const int min_y = std::max(staging_bbox_[2] - border, 0), max_y = std::min(staging_bbox_[3] + border, ny - 1);
  FinishedMap m;
  m.downsample = ds;
  m.resolution = geo_.resolution * ds;
  m.min_x = min_x;
  m.min_y = min_y;
  m.size_x = std::max(max_x - min_x, 0);  // CARMEN's max - min, no +1
  m.size_y = std::max(max_y - min_y, 0);
  const size_t n = static_cast<size_t>(m.size_x) * m.size_y;
  reserve(finished_, std::max<size_t>(n, 1));
  reserve(staging_out_, std::max<size_t>(n, 1));
  cuda::launch_crop(blocks_.get(), ny, min_x, min_y, m.size_x, m.size_y, finished_.get(), s);
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_out_.get(), finished_.get(), n * sizeof(float), cudaMemcpyDeviceToHost, s));
  VG_CUDA_CHECK(cudaStreamSynchronize(s));
  m.cells.assign(staging_out_.get(), staging_out_.get() + n);
  return m;
}

std::vector<float> CudaRenderer::read(const GridWindow &w) {
  const size_t n = static_cast<size_t>(w.width) * static_cast<size_t>(w.height);
  cudaStream_t s = stream_->get();
  reserve(window_, std::max<size_t>(n, 1));
  VG_CUDA_CHECK(cudaStreamSynchronize(s));
  reserve(staging_out_, std::max<size_t>(n, 1));
  cuda::launch_read_window(cells(), geo_.size_y, w.x0, w.y0, w.width, w.height, window_.get(), s);
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_out_.get(), window_.get(), n * sizeof(float), cudaMemcpyDeviceToHost, s));
  VG_CUDA_CHECK(cudaStreamSynchronize(s));
  return std::vector<float>(staging_out_.get(), staging_out_.get() + n);
}

void CudaRenderer::upload_grid(const float *probabilities) {
  const size_t cells = geo_.num_cells();
  reserve(grid_, cells);  // float mode: the probabilities pass through it
  VG_CUDA_CHECK(cudaMemcpy(grid_.get(), probabilities, cells * sizeof(float), cudaMemcpyHostToDevice));
  if (exact()) return;
  cuda::launch_float_from_prob(kernel_model_of<float>(params_, geo_), grid_.get(), sums_.get(), cells,
                               stream_->get());
  fixed_base_ = 1048576.0;  // from_prob's saturation
}

void CudaRenderer::forget_scans() { stored_beams_ = 0; }

std::unique_ptr<Renderer> make_cuda_renderer(const BackendOptions &options) {
  std::string why;
  if (!cuda_usable(options.cuda_device, &why)) throw std::runtime_error("no usable GPU: " + why);
  return std::make_unique<CudaRenderer>(options);
}

}  // namespace vasco
