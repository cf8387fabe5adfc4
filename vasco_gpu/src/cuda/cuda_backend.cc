// Host side of the CUDA backend: prepares a scan batch, uploads it once, runs
// every scan on the GPU, downloads the grid once (the paper's working cycle).
#include "vasco_gpu/cuda_backend.h"

#include <algorithm>
#include <cstddef>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <cmath>
#include <mutex>
#include <sstream>
#include <thread>
#include <vector>

#include "cuda_check.h"
#include "egrid_kernels.h"
#include "paper_kernels.h"
#include "vasco_gpu/beam_placement.h"
#include "vasco_gpu/oracle.h"

namespace vasco {
namespace {

using Clock = std::chrono::steady_clock;
using cuda::DeviceBuffer;
using cuda::Event;
using cuda::PinnedBuffer;
using cuda::Stream;

struct UsableState {
  std::once_flag once;
  bool usable = false;
  std::string why;
};

UsableState &usable_state() {
  static UsableState s;
  return s;
}

double seconds(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string mib(size_t bytes) {
  std::ostringstream s;
  s << (bytes + (1 << 20) - 1) / (1 << 20) << " MiB";
  return s.str();
}

// Refuses, with a clear message, a job whose device memory would not fit.
void check_fits(size_t bytes, const char *what) {
  size_t free_b = 0, total_b = 0;
  VG_CUDA_CHECK(cudaMemGetInfo(&free_b, &total_b));
  // Keep a margin for CUB scratch rounding and the context.
  if (bytes + (size_t(64) << 20) > free_b)
    throw std::runtime_error(std::string("the map does not fit in GPU memory: ") + what + " needs " +
                             mib(bytes) + ", " + mib(free_b) + " free of " + mib(total_b) +
                             " (use a coarser vasco_resolution or a CPU backend)");
}

// With VASCO_CUDA_PROFILE set, prints the time of each GPU stage to stderr
// (events between stages; for tuning, not for the benchmark table).
class StageTimer {
 public:
  explicit StageTimer(cudaStream_t s) : stream_(s), on_(std::getenv("VASCO_CUDA_PROFILE") != nullptr) {}
  void mark(const char *name) {
    if (!on_) return;
    events_.emplace_back(std::make_unique<Event>(), name);
    events_.back().first->record(stream_);
  }
  void report() {
    if (!on_ || events_.size() < 2) return;
    VG_CUDA_CHECK(cudaStreamSynchronize(stream_));
    for (size_t i = 1; i < events_.size(); ++i)
      std::fprintf(stderr, "  [cuda] %-14s %8.3f ms\n", events_[i].second,
                   events_[i].first->since(*events_[i - 1].first));
  }

 private:
  cudaStream_t stream_;
  bool on_;
  std::vector<std::pair<std::unique_ptr<Event>, const char *>> events_;
};

static_assert(sizeof(PlacedBeam) == sizeof(cuda::ExactBeam) &&
                  offsetof(PlacedBeam, x2) == offsetof(cuda::ExactBeam, x2) &&
                  offsetof(PlacedBeam, y2) == offsetof(cuda::ExactBeam, y2) &&
                  offsetof(PlacedBeam, scan) == offsetof(cuda::ExactBeam, scan) &&
                  offsetof(PlacedBeam, range) == offsetof(cuda::ExactBeam, range),
              "PlacedBeam is uploaded as cuda::ExactBeam");

class CudaBackend : public Backend {
 public:
  explicit CudaBackend(const BackendOptions &o) : options_(o) {
    VG_CUDA_CHECK(cudaSetDevice(o.cuda_device));
  }
  std::string name() const override {
    if (options_.cuda_mode == CudaMode::Exact) return "cuda_exact";
    switch (options_.cuda_kernel) {
      case CudaKernel::Ours: return "cuda_float";
      case CudaKernel::PaperPerScan: return "cuda_paper";
      case CudaKernel::PaperPerScanNoShared: return "cuda_paper_noshared";
      case CudaKernel::PaperPerScanNoConst: return "cuda_paper_noconst";
      case CudaKernel::PaperFused: return "cuda_paper_fused";
    }
    return "cuda_float";
  }

  std::vector<float> map(const ScanBatch &batch, const MapperParams &params,
                         const GridGeometry &geo, MapStats *stats) override {
    std::vector<float> grid(geo.num_cells());
    run(batch, 0, batch.num_scans(), params, geo, grid.data(), true, stats);
    return grid;
  }

  // Uploads `cells`, applies the scans on the GPU, downloads the grid back.
  void apply(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
             const GridGeometry &geo, float *cells, MapStats *stats) override {
    run(batch, first, last, params, geo, cells, false, stats);
  }

 private:
  // fresh: the grid starts all unknown (nothing uploaded); else from `cells`.
  void run(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
           const GridGeometry &geo, float *cells, bool fresh, MapStats *stats) {
    VG_CUDA_CHECK(cudaSetDevice(options_.cuda_device));
    MapStats st;
    last = std::min(last, batch.num_scans());
    first = std::min(first, last);
    if (options_.cuda_mode == CudaMode::Exact) {
      // Exact mode counts (tile, beam) pairs in 32 bits: a run of scans whose
      // pairs could pass 2^32 goes in several launches, each continuing the
      // grid of the one before (the same order of updates per cell).
      const uint64_t max_beams = exact_beams_per_launch(params);
      size_t a = first;
      do {
        size_t b = a;
        while (b < last && (b == a || batch.beam_offset[b + 1] - batch.beam_offset[a] <= max_beams)) ++b;
        MapStats part;
        map_exact(batch, a, b, params, geo, cells, fresh && a == first, &part);
        add_stats(&st, part);
        a = b;
      } while (a < last);
    } else {
      map_float(batch, first, last, params, geo, cells, fresh, &st);
    }
    st.scans = last - first;
    if (stats != nullptr) *stats = st;
  }

  // Beams per exact-mode launch such that the (tile, beam) pairs, at most
  // 2 * (table_size / kTile + 2) per beam (a monotone walk of table_size
  // cells enters that many tiles at most), stay below 2^32.
  static uint64_t exact_beams_per_launch(const MapperParams &p) {
    const uint64_t per_beam = 2 * (static_cast<uint64_t>(std::max(p.table_size(), 0)) / cuda::kTile + 2);
    return std::max<uint64_t>(1, (uint64_t(UINT32_MAX) - 1) / per_beam);
  }

  static void add_stats(MapStats *sum, const MapStats &part) {
    sum->beams_used += part.beams_used;
    sum->beams_skipped += part.beams_skipped;
    sum->cell_updates += part.cell_updates;
    sum->prep_s += part.prep_s;
    sum->upload_s += part.upload_s;
    sum->map_s += part.map_s;
    sum->download_s += part.download_s;
  }

  cuda::DeviceModel device_model(const MapperParams &p, const GridGeometry &geo) const {
    cuda::DeviceModel m;
    m.prior = p.p_prior;
    m.occ = p.p_occ;
    m.emp = p.p_emp;
    m.sure = p.range_sure;
    m.max = p.range_max;
    m.resolution = p.resolution;
    m.wall = p.wall_size;
    m.table_size = p.table_size();
    m.size_x = geo.size_x;
    m.size_y = geo.size_y;
    return m;
  }

  void map_exact(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
                 const GridGeometry &geo, float *host_grid, bool fresh, MapStats *st) {
    const auto t_prep = Clock::now();
    const cuda::DeviceModel m = device_model(params, geo);
    // Used beams only, in (scan, beam) order, their end cells computed by the
    // oracle's own code with the host's libm (DESIGN §2.2).
    const PlacedBeams placed = place_beams(batch, geo, params, 0, first, last);
    const size_t nb = placed.beams.size();
    st->beams_used = nb;
    st->beams_skipped = placed.skipped;
    std::vector<cuda::StartCell> h_starts(batch.num_scans());
    for (size_t s = 0; s < batch.num_scans(); ++s) h_starts[s] = {placed.starts[s].x1, placed.starts[s].y1};
    st->prep_s = seconds(t_prep);

    const int tiles_x = (geo.size_x + cuda::kTile - 1) / cuda::kTile;
    const int tiles_y = (geo.size_y + cuda::kTile - 1) / cuda::kTile;
    const size_t num_tiles = static_cast<size_t>(tiles_x) * tiles_y;
    const size_t T2 = static_cast<size_t>(m.table_size) * m.table_size;
    // Tables only when small (they replace a sqrt and two divisions per update).
    const bool use_tables = T2 <= (size_t(1) << 22);
    const size_t cells = geo.num_cells();
    const size_t scan_tmp = cuda::exact_scan_temp_bytes(nb);
    const size_t order_tmp = cuda::exact_order_temp_bytes(num_tiles);
    size_t fixed = nb * (sizeof(cuda::ExactBeam) + sizeof(cuda::LineRec) + 2 * sizeof(uint32_t)) +
                   batch.num_scans() * sizeof(cuda::StartCell) + cells * sizeof(float) +
                   6 * num_tiles * sizeof(uint32_t) + scan_tmp + order_tmp +
                   (use_tables ? 3 * T2 * sizeof(double) : 0);
    check_fits(fixed, "exact mode (beams, grid, tables)");

    Stream stream;
    Event e0, e_up, e_map, e_down;
    DeviceBuffer<cuda::ExactBeam> d_beams(nb);
    DeviceBuffer<cuda::StartCell> d_starts(batch.num_scans());
    DeviceBuffer<cuda::LineRec> d_lines(nb);
    DeviceBuffer<uint32_t> d_counts(nb + 1), d_offsets(nb + 1);
    DeviceBuffer<uint32_t> d_tile_begin(num_tiles), d_tile_end(num_tiles);
    DeviceBuffer<uint32_t> d_order(num_tiles), d_order_keys(num_tiles), d_order_keys_out(num_tiles),
        d_order_ids(num_tiles);
    DeviceBuffer<unsigned char> d_order_tmp(std::max<size_t>(order_tmp, 1));
    DeviceBuffer<float> d_grid(cells);
    DeviceBuffer<double> d_dist(use_tables ? T2 : 0), d_ff(use_tables ? T2 : 0), d_fo(use_tables ? T2 : 0);
    DeviceBuffer<unsigned long long> d_updates(1);
    DeviceBuffer<unsigned char> d_scan_tmp(std::max<size_t>(scan_tmp, 1));

    e0.record(stream.get());
    if (fresh)
      cuda::launch_fill(d_grid.get(), cells, egrid::kUnknown, stream.get());
    else
      VG_CUDA_CHECK(cudaMemcpyAsync(d_grid.get(), host_grid, cells * sizeof(float), cudaMemcpyHostToDevice,
                                    stream.get()));
    // PlacedBeam and cuda::ExactBeam are the same 16 bytes (checked above).
    if (nb) VG_CUDA_CHECK(cudaMemcpyAsync(d_beams.get(), placed.beams.data(), nb * sizeof(cuda::ExactBeam),
                                          cudaMemcpyHostToDevice, stream.get()));
    if (batch.num_scans())
      VG_CUDA_CHECK(cudaMemcpyAsync(d_starts.get(), h_starts.data(),
                                    batch.num_scans() * sizeof(cuda::StartCell),
                                    cudaMemcpyHostToDevice, stream.get()));
    e_up.record(stream.get());

    StageTimer timer(stream.get());
    timer.mark("start");
    VG_CUDA_CHECK(cudaMemsetAsync(d_updates.get(), 0, sizeof(unsigned long long), stream.get()));
    VG_CUDA_CHECK(cudaMemsetAsync(d_counts.get(), 0, (nb + 1) * sizeof(uint32_t), stream.get()));
    if (use_tables) cuda::launch_exact_tables(m, d_dist.get(), d_ff.get(), d_fo.get(), stream.get());
    timer.mark("tables");
    cuda::launch_exact_lines(m, d_beams.get(), d_starts.get(), nb, d_lines.get(), d_counts.get(),
                             stream.get());
    timer.mark("lines");
    cuda::exact_scan(d_counts.get(), d_offsets.get(), nb, d_scan_tmp.get(), scan_tmp, stream.get());
    timer.mark("scan");
    uint32_t num_pairs = 0;
    VG_CUDA_CHECK(cudaMemcpyAsync(&num_pairs, d_offsets.get() + nb, sizeof(uint32_t),
                                  cudaMemcpyDeviceToHost, stream.get()));
    stream.synchronize();
    const size_t sort_tmp = cuda::exact_sort_temp_bytes(num_pairs);
    check_fits(4 * size_t(num_pairs) * sizeof(uint32_t) + sort_tmp, "exact mode (tile lists)");
    DeviceBuffer<uint32_t> d_pair_tile(num_pairs), d_pair_beam(num_pairs);
    DeviceBuffer<uint32_t> d_sorted_tile(num_pairs), d_sorted_beam(num_pairs);
    DeviceBuffer<unsigned char> d_sort_tmp(std::max<size_t>(sort_tmp, 1));
    timer.mark("sync+alloc");
    cuda::launch_exact_pairs(m, d_lines.get(), d_offsets.get(), nb, d_pair_tile.get(),
                             d_pair_beam.get(), stream.get());
    timer.mark("pairs");
    int tile_bits = 1;
    while ((size_t(1) << tile_bits) < num_tiles) ++tile_bits;
    if (num_pairs)
      cuda::exact_sort(d_pair_tile.get(), d_sorted_tile.get(), d_pair_beam.get(), d_sorted_beam.get(),
                       num_pairs, tile_bits, d_sort_tmp.get(), sort_tmp, stream.get());
    timer.mark("sort");
    cuda::launch_exact_tile_ranges(d_sorted_tile.get(), num_pairs, d_tile_begin.get(),
                                   d_tile_end.get(), num_tiles, stream.get());
    timer.mark("ranges");
    cuda::exact_tile_order(d_tile_begin.get(), d_tile_end.get(), num_tiles, d_order.get(),
                           d_order_keys.get(), d_order_keys_out.get(), d_order_ids.get(),
                           d_order_tmp.get(), order_tmp, stream.get());
    timer.mark("order");
    cuda::launch_exact_tiles(m, d_lines.get(), d_sorted_beam.get(), d_order.get(), d_tile_begin.get(),
                             d_tile_end.get(), use_tables ? d_dist.get() : nullptr,
                             use_tables ? d_ff.get() : nullptr, use_tables ? d_fo.get() : nullptr,
                             d_grid.get(), d_updates.get(), stream.get());
    timer.mark("tiles");
    e_map.record(stream.get());

    unsigned long long updates = 0;
    VG_CUDA_CHECK(cudaMemcpyAsync(host_grid, d_grid.get(), cells * sizeof(float),
                                  cudaMemcpyDeviceToHost, stream.get()));
    VG_CUDA_CHECK(cudaMemcpyAsync(&updates, d_updates.get(), sizeof(updates), cudaMemcpyDeviceToHost,
                                  stream.get()));
    e_down.record(stream.get());
    stream.synchronize();
    timer.report();
    if (std::getenv("VASCO_CUDA_PROFILE"))
      std::fprintf(stderr, "  [cuda] %zu beams, %u tile pairs, %zu tiles\n", nb, num_pairs, num_tiles);
    st->cell_updates = updates;
    st->upload_s = e_up.since(e0) / 1e3;
    st->map_s = e_map.since(e_up) / 1e3;
    st->download_s = e_down.since(e_map) / 1e3;
  }

  void map_float(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
                 const GridGeometry &geo, float *host_grid, bool fresh, MapStats *st) {
    const auto t_prep = Clock::now();
    const std::vector<oracle::ScanStart> starts = place_scans(batch, geo);
    const size_t nscans = last - first;
    const uint64_t beam0 = batch.beam_offset[first];
    PinnedBuffer<cuda::FloatScan> h_scans(std::max<size_t>(nscans, 1));
    for (size_t s = first; s < last; ++s) {
      cuda::FloatScan f;
      f.lx = static_cast<float>(starts[s].lx);
      f.ly = static_cast<float>(starts[s].ly);
      f.theta = static_cast<float>(starts[s].theta);
      f.x1 = starts[s].x1;
      f.y1 = starts[s].y1;
      f.first = static_cast<float>(batch.first_angle[s]);
      f.step = static_cast<float>(batch.angle_step[s]);
      f.beam_begin = static_cast<uint32_t>(batch.beam_offset[s] - beam0);
      f.beam_count = batch.beams_in(s);
      h_scans[s - first] = f;
    }
    cuda::FloatModel m;
    m.prior = static_cast<float>(params.p_prior);
    m.occ = static_cast<float>(params.p_occ);
    m.emp = static_cast<float>(params.p_emp);
    m.sure = static_cast<float>(params.range_sure);
    m.max = static_cast<float>(params.range_max);
    m.resolution = static_cast<float>(params.resolution);
    m.wall = static_cast<float>(params.wall_size);
    m.logodds_prior = static_cast<float>(std::log(params.p_prior / (1 - params.p_prior)));
    m.table_size = params.table_size();
    m.size_x = geo.size_x;
    m.size_y = geo.size_y;
    st->prep_s = seconds(t_prep);

    const size_t cells = geo.num_cells(), nbeams = batch.beam_offset[last] - beam0;
    if (nbeams > UINT32_MAX) throw std::runtime_error("cuda float mode: more than 2^32 beams in one call");
    check_fits(cells * (sizeof(float) + 1) + nbeams * sizeof(float) + nscans * sizeof(cuda::FloatScan),
               "float mode (grid and beams)");
    Stream stream;
    Event e0, e_up, e_map, e_down;
    DeviceBuffer<cuda::FloatScan> d_scans(nscans);
    DeviceBuffer<float> d_ranges(nbeams), d_grid(cells);
    DeviceBuffer<uint8_t> d_touched(options_.cuda_kernel == CudaKernel::Ours ? 0 : cells);
    DeviceBuffer<unsigned long long> d_counters(3);
    DeviceBuffer<cuda::FloatModel> d_model(1);

    e0.record(stream.get());
    if (nscans)
      VG_CUDA_CHECK(cudaMemcpyAsync(d_scans.get(), h_scans.get(), nscans * sizeof(cuda::FloatScan),
                                    cudaMemcpyHostToDevice, stream.get()));
    if (nbeams)
      VG_CUDA_CHECK(cudaMemcpyAsync(d_ranges.get(), batch.range.data() + beam0, nbeams * sizeof(float),
                                    cudaMemcpyHostToDevice, stream.get()));
    e_up.record(stream.get());
    StageTimer timer(stream.get());
    timer.mark("start");
    const bool ours = options_.cuda_kernel == CudaKernel::Ours;
    if (ours && fresh) {
      cuda::launch_float_clear(d_grid.get(), cells, stream.get());
    } else if (ours) {
      VG_CUDA_CHECK(cudaMemcpyAsync(d_grid.get(), host_grid, cells * sizeof(float), cudaMemcpyHostToDevice,
                                    stream.get()));
      cuda::launch_float_from_prob(m, d_grid.get(), cells, stream.get());
    } else {
      if (!fresh) throw std::logic_error("the paper's kernels map whole batches only");
      VG_CUDA_CHECK(cudaMemsetAsync(d_grid.get(), 0, cells * sizeof(float), stream.get()));
      VG_CUDA_CHECK(cudaMemsetAsync(d_touched.get(), 0, cells, stream.get()));
    }
    timer.mark("clear");
    VG_CUDA_CHECK(cudaMemsetAsync(d_counters.get(), 0, 3 * sizeof(unsigned long long), stream.get()));
    if (ours) {
      cuda::launch_float_map(m, d_scans.get(), static_cast<int>(nscans), d_ranges.get(),
                             d_grid.get(), d_counters.get(), stream.get());
    } else {
      cuda::PaperVariant v = cuda::PaperVariant::PerScan;
      if (options_.cuda_kernel == CudaKernel::PaperPerScanNoShared) v = cuda::PaperVariant::PerScanNoShared;
      if (options_.cuda_kernel == CudaKernel::PaperPerScanNoConst) v = cuda::PaperVariant::PerScanNoConst;
      if (options_.cuda_kernel == CudaKernel::PaperFused) v = cuda::PaperVariant::Fused;
      VG_CUDA_CHECK(cudaMemcpyAsync(d_model.get(), &m, sizeof m, cudaMemcpyHostToDevice, stream.get()));
      cuda::run_paper_variant(v, m, d_model.get(), h_scans.get(), d_scans.get(),
                              static_cast<int>(nscans), d_ranges.get(), d_grid.get(),
                              d_touched.get(), stream.get());
    }
    timer.mark("map");
    cuda::launch_float_finalize(m, d_grid.get(), ours ? nullptr : d_touched.get(), cells,
                                stream.get());
    timer.mark("finalize");
    e_map.record(stream.get());
    unsigned long long counters[3] = {0, 0, 0};
    VG_CUDA_CHECK(cudaMemcpyAsync(host_grid, d_grid.get(), cells * sizeof(float),
                                  cudaMemcpyDeviceToHost, stream.get()));
    VG_CUDA_CHECK(cudaMemcpyAsync(counters, d_counters.get(), sizeof counters, cudaMemcpyDeviceToHost,
                                  stream.get()));
    e_down.record(stream.get());
    stream.synchronize();
    timer.report();
    if (options_.cuda_kernel == CudaKernel::Ours) {
      st->beams_used = counters[0];
      st->beams_skipped = counters[1];
      st->cell_updates = counters[2];
    }
    st->upload_s = e_up.since(e0) / 1e3;
    st->map_s = e_map.since(e_up) / 1e3;
    st->download_s = e_down.since(e_map) / 1e3;
  }

  BackendOptions options_;
};

}  // namespace

bool cuda_usable(int device, std::string *why) {
  UsableState &s = usable_state();
  std::call_once(s.once, [&] {
    int count = 0;
    cudaError_t err = cudaGetDeviceCount(&count);
    if (err != cudaSuccess) {
      s.why = std::string("no CUDA device (") + cudaGetErrorString(err) + ")";
      return;
    }
    if (device < 0 || device >= count) {
      s.why = "CUDA device " + std::to_string(device) + " does not exist (" + std::to_string(count) +
              " present)";
      return;
    }
    cudaDeviceProp prop;
    err = cudaGetDeviceProperties(&prop, device);
    if (err == cudaSuccess) err = cudaSetDevice(device);
    if (err == cudaSuccess) err = cudaFree(nullptr);  // creates the context
    if (err != cudaSuccess) {
      s.why = std::string("CUDA device ") + std::to_string(device) + " is not usable (" +
              cudaGetErrorString(err) + ")";
      return;
    }
    if (prop.major < 9) {
      s.why = std::string(prop.name) + " is compute capability " + std::to_string(prop.major) + "." +
              std::to_string(prop.minor) + "; this build targets sm_90";
      return;
    }
    s.usable = true;
  });
  if (!s.usable && why != nullptr) *why = s.why;
  return s.usable;
}

std::string cuda_device_description(int device) {
  cudaDeviceProp prop;
  if (cudaGetDeviceProperties(&prop, device) != cudaSuccess) return "unknown device";
  std::ostringstream o;
  o << prop.name << ", " << prop.multiProcessorCount << " SMs, "
    << prop.totalGlobalMem / (1024.0 * 1024 * 1024) << " GiB";
  return o.str();
}

std::unique_ptr<Backend> make_cuda_backend(const BackendOptions &options) {
  std::string why;
  if (!cuda_usable(options.cuda_device, &why)) throw std::runtime_error("no usable GPU: " + why);
  return std::make_unique<CudaBackend>(options);
}

}  // namespace vasco
