// CUDA exact mode, in three parts per launch: place the beams (on the
// device, device_placement.h, or on the host into pinned staging and
// uploaded); list (tile, beam) pairs; apply them tile by tile. The pair
// arrays are sized by a bound on the pairs that the placement sums
// (exact_tile_bound.h), so no part waits for the real count.
#include "cuda_exact_renderer.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

#include "exact_pair_bound.h"
#include "vasco_gpu/internal/beam_placement.h"

namespace vasco {

using cuda_host::grow_to;

// kTile x kTile tiles of a grid, in 64 bits (sides up to kMaxGridSide).
size_t CudaExactRenderer::tiles_of(const GridGeometry &geo) {
  const int64_t tx = (static_cast<int64_t>(geo.size_x) + cuda::kTile - 1) / cuda::kTile;
  const int64_t ty = (static_cast<int64_t>(geo.size_y) + cuda::kTile - 1) / cuda::kTile;
  return static_cast<size_t>(tx) * static_cast<size_t>(ty);
}

// The grid's floats and, per tile, its list's bounds, the run order and the
// order's sort keys and ids (six uint32) and the sort's scratch: about 4.5
// bytes a cell. They are checked together against the device's free memory
// and allocated with the grid, so that an apply never runs out of them.
double CudaExactRenderer::device_bytes_per_cell() const {
  return sizeof(float) + (6.0 * sizeof(uint32_t) + 2.0 * sizeof(uint32_t)) / (cuda::kTile * cuda::kTile);
}

void CudaExactRenderer::reserve_grid(const GridGeometry &geo) {
  const size_t tiles = tiles_of(geo);
  if (tiles > cuda::kMaxExactTiles)
    throw Error(ErrorCode::TooLarge,
                "cuda exact mode: a grid of " + std::to_string(geo.size_x) + " x " + std::to_string(geo.size_y) +
                    " cells has " + std::to_string(tiles) + " tiles of " + std::to_string(cuda::kTile) + " x " +
                    std::to_string(cuda::kTile) + " cells, more than the " + std::to_string(cuda::kMaxExactTiles) +
                    " its tile ids and its launch can count; use cuda float mode or a CPU backend");
  const size_t order_tmp = std::max<size_t>(cuda::exact_order_temp_bytes(tiles), 1);
  const auto per_tile = {&tile_begin_, &tile_end_, &order_, &order_keys_, &order_keys_out_, &order_ids_};
  size_t scratch = cuda_host::growth_bytes(order_tmp_, order_tmp);
  for (auto *b : per_tile) scratch += cuda_host::growth_bytes(*b, tiles);
  grow_grid(grid_, geo, scratch);
  for (auto *b : per_tile) grow_to(*b, tiles);
  grow_to(order_tmp_, order_tmp);
}

void CudaExactRenderer::clear_grid() {
  cuda::launch_fill(grid_.get(), grid_geo().num_cells(), egrid::kUnknown, stream());
}

cuda::GridCells CudaExactRenderer::cells() const {
  cuda::GridCells c;
  c.probs = grid_.get();
  return c;
}

// The tables for the current parameters, built when they change.
void CudaExactRenderer::ensure_tables() {
  const int T = params().table_size();
  use_tables_ = T > 0 && T <= cuda::kMaxExactTable && !cuda_host::tables_disabled();
  if (!use_tables_) return;
  tables_key_.ensure(params(), [&] {
    grow_to(factors_, static_cast<size_t>(T) * static_cast<size_t>(T));
    grow_to(reach_, static_cast<size_t>(T));
    cuda::launch_exact_tables(kernel_model_of<double>(params(), grid_geo()), factors_.get(), reach_.get(), stream());
  });
}

// (tile, beam) pairs are counted in 32 bits: a run of scans that could pass
// 2^32 of them goes in several launches, each continuing the grid (a failure
// after the first leaves the grid lost).
void CudaExactRenderer::apply_scans(const ScanBatch &scans, size_t first, size_t last, MapStats *st) {
  ensure_tables();
  const bool on_device = !cuda_host::host_placement_forced();
  if (on_device) placement_.ranges().upload(scans, last, stream());
  const uint64_t max_beams = cuda_host::exact_beams_per_launch(params().table_size());
  for (size_t a = first; a < last;) {
    size_t b = a + 1;
    while (b < last && scans.beam_offset[b + 1] - scans.beam_offset[a] <= max_beams) ++b;
    apply_launch(scans, a, b, on_device, st);
    a = b;
  }
  if (on_device) placement_.ranges().commit();
  end_update();
}

void CudaExactRenderer::apply_launch(const ScanBatch &scans, size_t first, size_t last, bool on_device,
                                     MapStats *st) {
  const auto t_prep = std::chrono::steady_clock::now();
  uint64_t pair_bound = 0;
  const bool placed = on_device && place_on_device(scans, first, last, st, &pair_bound);
  if (!placed) pair_bound = place_beams(scans, first, last, st);
  st->prep_s += seconds_since(t_prep);
  if (beams_ == 0) return;
  launch_apply(pair_bound, !placed, st);
}

// The beams of scans [first, last) placed on the device into beams_dev_ and
// starts_; false when the device left too many for the host (nothing
// counted then: the caller places them on the host).
bool CudaExactRenderer::place_on_device(const ScanBatch &scans, size_t first, size_t last, MapStats *st,
                                        uint64_t *pair_bound) {
  const cuda_host::DevicePlacement::Placed p =
      placement_.place(scans, first, last, geo(), params(), beams_dev_, starts_, stream());
  if (std::getenv("VASCO_CUDA_PROFILE"))
    std::fprintf(stderr, "  [cuda] placed on the device: %llu beams, %llu unsure%s\n",
                 static_cast<unsigned long long>(p.beams), static_cast<unsigned long long>(p.unsure),
                 p.done ? "" : " (too many: placed on the host)");
  if (!p.done) return false;
  beams_ = p.beams;
  scans_ = last - first;
  st->beams_used += p.beams;
  st->beams_skipped += p.skipped;
  *pair_bound = p.pair_bound;
  return true;
}

// Places the beams of scans [first, last) with the oracle's code, on every
// core, straight into the pinned staging buffer; returns the bound on their
// (tile, beam) pairs.
uint64_t CudaExactRenderer::place_beams(const ScanBatch &scans, size_t first, size_t last, MapStats *st) {
  const BeamLayout layout = lay_out_beams(scans, geo(), 0, first, last);
  beams_ = layout.used();
  scans_ = layout.starts.size();
  st->beams_used += beams_;
  st->beams_skipped += layout.skipped;
  VG_CUDA_CHECK(cudaStreamSynchronize(stream()));  // staging is free (every call ends idle)
  grow_to(staging_beams_, std::max<uint64_t>(beams_, 1));
  grow_to(staging_starts_, std::max<size_t>(scans_, 1));
  PlacedBeam *beams = staging_beams_.get();
  place_laid_out_beams(scans, geo(), params(), layout, 0, beams);
  for (size_t s = 0; s < scans_; ++s) staging_starts_[s] = {layout.starts[s].x1, layout.starts[s].y1};
  // The bound counts tile borders crossed in the frame; a band starts on a
  // tile border (split_renderer.h), so it holds for a band's tiles too.
  return cuda_host::exact_pair_bound(beams, beams_, layout.starts, params().table_size());
}

void CudaExactRenderer::reserve_scratch(uint64_t pair_bound, size_t tiles) {
  const size_t nb = beams_, ns = scans_;
  grow_to(beams_dev_, nb);
  grow_to(starts_, ns);
  grow_to(lines_, nb);
  grow_to(counts_, nb + 1);
  grow_to(offsets_, nb + 1);
  for (auto *b : {&tile_begin_, &tile_end_, &order_, &order_keys_, &order_keys_out_, &order_ids_}) grow_to(*b, tiles);
  grow_to(scan_tmp_, std::max<size_t>(cuda::exact_scan_temp_bytes(nb), 1));
  grow_to(order_tmp_, std::max<size_t>(cuda::exact_order_temp_bytes(tiles), 1));
  grow_to(updates_, 2);
  grow_to(heavy_count_, 1);
  grow_to(staging_counters_, 2);
  const size_t pairs = std::max<size_t>(pair_bound, 1);
  if (pairs > pair_tile_.size())
    cuda_host::check_fits(4 * (cuda_host::grown_size(pair_tile_.size(), pairs) - pair_tile_.size()) * sizeof(uint32_t),
                          "exact mode (tile lists)");
  for (auto *b : {&pair_tile_, &pair_beam_, &sorted_tile_, &sorted_beam_}) grow_to(*b, pairs);
  grow_to(sort_tmp_, std::max<size_t>(cuda::exact_sort_temp_bytes(pairs), 1));
}

// The (tile, beam) pairs of the uploaded beams, sorted by tile in (scan,
// beam) order, each tile's slice, and the order to run the tiles in.
void CudaExactRenderer::launch_tile_lists(const cuda::KernelModel<double> &m, uint64_t pair_bound, size_t tiles,
                                          cudaStream_t s, cuda_host::StageTimer &timer) {
  const size_t nb = beams_;
  VG_CUDA_CHECK(cudaMemsetAsync(updates_.get(), 0, 2 * sizeof(unsigned long long), s));
  VG_CUDA_CHECK(cudaMemsetAsync(counts_.get(), 0, (nb + 1) * sizeof(uint32_t), s));
  cuda::launch_exact_lines(m, beams_dev_.get(), starts_.get(), nb, lines_.get(), counts_.get(), s);
  timer.mark("lines");
  cuda::exact_scan(counts_.get(), offsets_.get(), nb, scan_tmp_.get(), scan_tmp_.size(), s);
  timer.mark("scan");
  cuda::launch_exact_pairs(m, lines_.get(), offsets_.get(), nb, pair_bound, pair_tile_.get(), pair_beam_.get(),
                           updates_.get() + 1, s);
  timer.mark("pairs");
  // kNoTile's low tile_bits bits must not name a tile: 2^tile_bits > tiles.
  const int tile_bits = cuda::key_bits_above(tiles);
  if (pair_bound)
    cuda::exact_sort(pair_tile_.get(), sorted_tile_.get(), pair_beam_.get(), sorted_beam_.get(), pair_bound,
                     tile_bits, sort_tmp_.get(), sort_tmp_.size(), s);
  timer.mark("sort");
  cuda::launch_exact_tile_ranges(sorted_tile_.get(), pair_bound, tile_begin_.get(), tile_end_.get(), tiles, s);
  cuda::exact_tile_order(tile_begin_.get(), tile_end_.get(), tiles, nb, order_.get(), order_keys_.get(),
                         order_keys_out_.get(), order_ids_.get(), heavy_count_.get(), order_tmp_.get(),
                         order_tmp_.size(), s);
  timer.mark("tile order");
}

// Allocates every scratch buffer first; the grid changes only in the tiles
// kernel.
void CudaExactRenderer::launch_apply(uint64_t pair_bound, bool upload_beams, MapStats *st) {
  const cuda::KernelModel<double> m = kernel_model_of<double>(params(), grid_geo(), band_x0());
  const size_t tiles = num_tiles();
  reserve_scratch(pair_bound, tiles);
  if (!side_stream_) {
    side_stream_ = std::make_unique<cuda::Stream>(cuda::Stream::Highest{});  // the heavy tiles' (exact_tiles.cu)
    fork_ = std::make_unique<cuda::Event>();
    join_ = std::make_unique<cuda::Event>();
  }
  PhaseEvents &ev = events();
  cudaStream_t s = stream();
  ev.start.record(s);
  if (upload_beams) {
    VG_CUDA_CHECK(cudaMemcpyAsync(beams_dev_.get(), staging_beams_.get(), beams_ * sizeof(PlacedBeam),
                                  cudaMemcpyHostToDevice, s));
    VG_CUDA_CHECK(cudaMemcpyAsync(starts_.get(), staging_starts_.get(), scans_ * sizeof(cuda::StartCell),
                                  cudaMemcpyHostToDevice, s));
  }
  ev.uploaded.record(s);
  cuda_host::StageTimer timer(s);
  timer.mark("start");
  launch_tile_lists(m, pair_bound, tiles, s, timer);
  begin_update();
  cuda::launch_exact_tiles(m, lines_.get(), sorted_beam_.get(), order_.get(), tile_begin_.get(), tile_end_.get(),
                           heavy_count_.get(), use_tables_ ? factors_.get() : nullptr, use_tables_ ? reach_.get() : nullptr,
                           grid_.get(), updates_.get(), {s, side_stream_->get(), fork_->get(), join_->get()});
  timer.mark("tiles");
  ev.mapped.record(s);
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_counters_.get(), updates_.get(), 2 * sizeof(unsigned long long),
                                cudaMemcpyDeviceToHost, s));
  VG_CUDA_CHECK(cudaStreamSynchronize(s));  // the call's result is complete
  if (staging_counters_[1] != 0)
    throw Error(ErrorCode::Internal, "cuda exact mode: (tile, beam) pairs past the host's bound, or not as counted (a bug)");
  timer.report();
  if (std::getenv("VASCO_CUDA_PROFILE")) report_tile_lists(pair_bound, tiles);
  st->cell_updates += staging_counters_[0];
  ev.add_times(st);
}

// Profiling only (VASCO_CUDA_PROFILE): the pairs and the longest tile
// lists, which bound the tile kernel (a tile's list runs in order).
void CudaExactRenderer::report_tile_lists(uint64_t pair_bound, size_t tiles) {
  std::vector<uint32_t> begin(tiles), end(tiles);
  VG_CUDA_CHECK(cudaMemcpy(begin.data(), tile_begin_.get(), tiles * 4, cudaMemcpyDeviceToHost));
  VG_CUDA_CHECK(cudaMemcpy(end.data(), tile_end_.get(), tiles * 4, cudaMemcpyDeviceToHost));
  uint64_t pairs = 0;
  size_t empty = 0;
  std::vector<uint32_t> len(tiles);
  for (size_t t = 0; t < tiles; ++t) {
    pairs += len[t] = end[t] - begin[t];
    empty += len[t] == 0;
  }
  std::sort(len.begin(), len.end(), std::greater<uint32_t>());
  std::fprintf(stderr, "  [cuda] beams %llu, pairs %llu (bound %llu), tiles %zu (%zu no beam crosses), longest lists %u %u %u %u\n",
               static_cast<unsigned long long>(beams_), static_cast<unsigned long long>(pairs),
               static_cast<unsigned long long>(pair_bound), tiles, empty, len.size() > 0 ? len[0] : 0,
               len.size() > 1 ? len[1] : 0, len.size() > 2 ? len[2] : 0, len.size() > 3 ? len[3] : 0);
}

}  // namespace vasco
