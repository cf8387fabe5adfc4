// The paper's kernel and its ablation variants as a one-shot backend (see
// paper_backend.h).
#include "paper_backend.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <vector>

#include "cuda_check.h"
#include "cuda_host_support.h"
#include "egrid_kernels.h"
#include "vasco_gpu/internal/beam_placement.h"
#include "vasco_gpu/cuda_backend.h"

namespace vasco {
namespace {

using Clock = std::chrono::steady_clock;
using cuda::DeviceBuffer;
using cuda::Event;
using cuda::PinnedBuffer;
using cuda::Stream;
using cuda_host::check_fits;
using cuda_host::StageTimer;

class PaperBackend : public PaperMapper {
 public:
  PaperBackend(cuda::PaperVariant v, int device) : variant_(v), device_(device) {
    VG_CUDA_CHECK(cudaSetDevice(device));
  }
  std::string name() const override { return cuda::paper_variant_name(variant_); }

  std::vector<float> map(const ScanBatch &batch, const MapperParams &params, const GridGeometry &geo,
                         MapStats *stats) override {
    VG_CUDA_CHECK(cudaSetDevice(device_));
    check_fits(2 * geo.num_cells() * sizeof(float), "the evidence grid");
    std::vector<float> grid(geo.num_cells());
    MapStats st;
    map_paper(batch, params, geo, grid.data(), &st);
    st.scans = batch.num_scans();
    if (stats != nullptr) *stats = st;
    return grid;
  }

 private:
  // Uploads the batch once, runs every scan with the variant's kernels,
  // downloads the grid once (the paper's working cycle).
  void map_paper(const ScanBatch &batch, const MapperParams &params, const GridGeometry &geo,
                 float *host_grid, MapStats *st) {
    const auto t_prep = Clock::now();
    const std::vector<oracle::ScanStart> starts = place_scans(batch, geo);
    const size_t nscans = batch.num_scans();
    PinnedBuffer<cuda::FloatScan> h_scans(std::max<size_t>(nscans, 1));
    for (size_t s = 0; s < nscans; ++s) {
      cuda::FloatScan f;
      f.lx = static_cast<float>(starts[s].lx);
      f.ly = static_cast<float>(starts[s].ly);
      f.theta = static_cast<float>(starts[s].theta);
      f.x1 = starts[s].x1;
      f.y1 = starts[s].y1;
      f.first = static_cast<float>(batch.first_angle[s]);
      f.step = static_cast<float>(batch.angle_step[s]);
      f.beam_begin = static_cast<uint32_t>(batch.beam_offset[s]);
      f.beam_count = batch.beams_in(s);
      h_scans[s] = f;
    }
    const cuda::KernelModel<float> m = kernel_model_of<float>(params, geo);
    st->prep_s = seconds_since(t_prep);

    const size_t cells = geo.num_cells(), nbeams = batch.num_beams();
    if (nbeams > UINT32_MAX) throw std::runtime_error("the paper's kernels: more than 2^32 beams");
    check_fits(cells * (sizeof(float) + 1) + nbeams * sizeof(float) + nscans * sizeof(cuda::FloatScan),
               "float mode (grid and beams)");
    // A floor of our kernel (mapping_bench's ablation) runs on its tables and fixed-point sums.
    const bool floor = variant_ == cuda::PaperVariant::FloorRegisters || variant_ == cuda::PaperVariant::FloorSharedTile;
    const int T = params.table_size();
    if (floor && (T <= 0 || T > cuda::kMaxFloatTable))
      throw std::runtime_error("the float floors: no increment tables for these parameters");
    const size_t table_cells = floor ? static_cast<size_t>(T) * static_cast<size_t>(T) : 0;
    if (floor) check_fits(cells * sizeof(unsigned long long) + table_cells * sizeof(int2), "the float floors (sums and tables)");
    Stream stream;
    Event e0, e_up, e_map, e_down, e_floor0, e_floor1;
    DeviceBuffer<cuda::FloatScan> d_scans(nscans);
    DeviceBuffer<float> d_ranges(nbeams), d_grid(cells);
    DeviceBuffer<uint8_t> d_touched(cells);
    DeviceBuffer<unsigned long long> d_counters(3);
    DeviceBuffer<cuda::KernelModel<float>> d_model(1);
    DeviceBuffer<int2> increments(table_cells);
    DeviceBuffer<unsigned long long> sums(floor ? cells : 0);  // a degenerate beam still adds to its cell
    if (floor) cuda::launch_float_tables(m, increments.get(), stream.get());

    e0.record(stream.get());
    if (nscans)
      VG_CUDA_CHECK(cudaMemcpyAsync(d_scans.get(), h_scans.get(), nscans * sizeof(cuda::FloatScan),
                                    cudaMemcpyHostToDevice, stream.get()));
    if (nbeams)
      VG_CUDA_CHECK(cudaMemcpyAsync(d_ranges.get(), batch.range.data(), nbeams * sizeof(float),
                                    cudaMemcpyHostToDevice, stream.get()));
    e_up.record(stream.get());
    StageTimer timer(stream.get());
    timer.mark("start");
    VG_CUDA_CHECK(cudaMemsetAsync(d_grid.get(), 0, cells * sizeof(float), stream.get()));
    VG_CUDA_CHECK(cudaMemsetAsync(d_touched.get(), 0, cells, stream.get()));
    timer.mark("clear");
    VG_CUDA_CHECK(cudaMemsetAsync(d_counters.get(), 0, 3 * sizeof(unsigned long long), stream.get()));
    const cuda::PaperVariant v = variant_;
    VG_CUDA_CHECK(cudaMemcpyAsync(d_model.get(), &m, sizeof m, cudaMemcpyHostToDevice, stream.get()));
    if (floor) {
      // Our kernel's walk with its tables (built before the launch, as a
      // session builds them once), the updates where the floor puts them.
      const cuda::FloatFloor where =
          v == cuda::PaperVariant::FloorRegisters ? cuda::FloatFloor::Registers : cuda::FloatFloor::SharedTile;
      // Timed alone, as the library's rows time their kernels (not the clears and finalize around them).
      e_floor0.record(stream.get());
      cuda::launch_float_map_floor(where, m, increments.get(), d_scans.get(), static_cast<int>(nscans),
                                   d_ranges.get(), sums.get(), d_counters.get(), stream.get());
      e_floor1.record(stream.get());
    } else {
      cuda::run_paper_variant(v, m, d_model.get(), h_scans.get(), d_scans.get(), static_cast<int>(nscans),
                              d_ranges.get(), d_grid.get(), d_touched.get(), stream.get());
    }
    timer.mark("map");
    cuda::launch_float_finalize(m, d_grid.get(), d_touched.get(), cells, stream.get());
    timer.mark("finalize");
    e_map.record(stream.get());
    VG_CUDA_CHECK(cudaMemcpyAsync(host_grid, d_grid.get(), cells * sizeof(float),
                                  cudaMemcpyDeviceToHost, stream.get()));
    e_down.record(stream.get());
    stream.synchronize();
    timer.report();
    st->upload_s = e_up.since(e0) / 1e3;
    st->map_s = (floor ? e_floor1.since(e_floor0) : e_map.since(e_up)) / 1e3;
    st->download_s = e_down.since(e_map) / 1e3;
  }

  cuda::PaperVariant variant_;
  int device_;
};

}  // namespace

std::unique_ptr<PaperMapper> make_paper_mapper(cuda::PaperVariant variant, int cuda_device) {
  std::string why;
  if (!cuda_usable(cuda_device, &why)) throw std::runtime_error("no usable GPU: " + why);
  return std::make_unique<PaperBackend>(variant, cuda_device);
}

}  // namespace vasco
