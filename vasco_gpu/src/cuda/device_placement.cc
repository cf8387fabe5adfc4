#include "device_placement.h"

#include <algorithm>

#include "vasco_gpu/internal/beam_placement.h"

namespace vasco {
namespace cuda_host {
namespace {

// Unsure beams one launch lists for the host: a few in 10^7 are expected;
// past this many (a synthetic log of poses on cell corners, say) the launch
// is placed on the host instead.
constexpr uint32_t kUnsureCapacity = 1 << 14;

}  // namespace

// The scans' records: their starts placed by the oracle's code on the host
// (sequential: the first scan fixes the frame), beam 0's angle as
// oracle::SteppedAngles starts it.
void DevicePlacement::stage_scans(const ScanBatch &scans, size_t first, size_t last, const GridGeometry &geo) {
  starts_host_ = place_scans(scans, geo, first, last);
  const size_t n = last - first;
  grow_to(staging_scans_, std::max<size_t>(n, 1));
  grow_to(staging_starts_, std::max<size_t>(n, 1));
  const uint64_t base = scans.beam_offset[first];
  for (size_t i = 0; i < n; ++i) {
    const oracle::ScanStart &p = starts_host_[i];
    const size_t s = first + i;
    cuda::ExactScan &r = staging_scans_[i];
    r.lx = p.lx;
    r.ly = p.ly;
    r.angle0 = p.theta + scans.first_angle[s];
    r.step = scans.angle_step[s];
    r.beam_begin = static_cast<uint32_t>(scans.beam_offset[s] - base);
    r.beam_count = scans.beams_in(s);
    r.x1 = p.x1;
    r.y1 = p.y1;
    staging_starts_[i] = {p.x1, p.y1};
  }
}

void DevicePlacement::reserve_scratch(size_t num_beams, size_t num_scans) {
  const char *what = "exact mode (beam placement)";
  const size_t nb = std::max<size_t>(num_beams, 1);
  grow_to_checked(scans_dev_, std::max<size_t>(num_scans, 1), what);
  grow_to_checked(used_, nb + 1, what);
  grow_to_checked(slots_, nb + 1, what);
  grow_to_checked(scan_tmp_, std::max<size_t>(cuda::exact_scan_temp_bytes(num_beams), 1), what);
  grow_to(unsure_, kUnsureCapacity);
  grow_to(counters_, 2);
  grow_to(staging_counters_, 2);
  grow_to(staging_used_, 1);
}

DevicePlacement::Placed DevicePlacement::place(const ScanBatch &scans, size_t first, size_t last,
                                               const GridGeometry &geo, const MapperParams &params,
                                               cuda::DeviceBuffer<PlacedBeam> &beams,
                                               cuda::DeviceBuffer<cuda::StartCell> &starts, cudaStream_t stream) {
  const size_t ns = last - first;
  const uint64_t nb = scans.beam_offset[last] - scans.beam_offset[first];
  VG_CUDA_CHECK(cudaStreamSynchronize(stream));  // the staging buffers are free
  stage_scans(scans, first, last, geo);
  reserve_scratch(nb, ns);
  grow_to_checked(beams, std::max<uint64_t>(nb, 1), "exact mode (placed beams)");
  grow_to(starts, std::max<size_t>(ns, 1));
  VG_CUDA_CHECK(cudaMemcpyAsync(scans_dev_.get(), staging_scans_.get(), ns * sizeof(cuda::ExactScan),
                                cudaMemcpyHostToDevice, stream));
  VG_CUDA_CHECK(cudaMemcpyAsync(starts.get(), staging_starts_.get(), ns * sizeof(cuda::StartCell),
                                cudaMemcpyHostToDevice, stream));
  VG_CUDA_CHECK(cudaMemsetAsync(counters_.get(), 0, 2 * sizeof(unsigned long long), stream));
  const float *ranges = ranges_.get() + scans.beam_offset[first];
  const cuda::PlacementModel m{geo.resolution, params.wall_size, params.table_size()};
  cuda::launch_exact_used(ranges, nb, used_.get(), stream);
  cuda::exact_scan(used_.get(), slots_.get(), nb, scan_tmp_.get(), scan_tmp_.size(), stream);
  cuda::launch_exact_place(m, scans_dev_.get(), static_cast<int>(ns), ranges, slots_.get(), beams.get(), unsure_.get(),
                           kUnsureCapacity, counters_.get(), stream);
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_counters_.get(), counters_.get(), 2 * sizeof(unsigned long long),
                                cudaMemcpyDeviceToHost, stream));
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_used_.get(), slots_.get() + nb, sizeof(uint32_t), cudaMemcpyDeviceToHost,
                                stream));
  VG_CUDA_CHECK(cudaStreamSynchronize(stream));
  Placed out;
  out.unsure = staging_counters_[1];
  if (out.unsure > kUnsureCapacity) return out;
  out.done = true;
  out.beams = staging_used_[0];
  out.skipped = nb - out.beams;
  out.pair_bound = staging_counters_[0];
  if (out.unsure) fix_unsure(static_cast<size_t>(out.unsure), m, beams.get(), stream);
  return out;
}

// The unsure beams' end cells by the oracle's own code (host libm), written
// over the device's.
void DevicePlacement::fix_unsure(size_t n, const cuda::PlacementModel &m, PlacedBeam *device_beams,
                                 cudaStream_t stream) {
  grow_to(staging_unsure_, n);
  grow_to(staging_fixes_, n);
  grow_to(fixes_, n);
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_unsure_.get(), unsure_.get(), n * sizeof(cuda::UnsureBeam),
                                cudaMemcpyDeviceToHost, stream));
  VG_CUDA_CHECK(cudaStreamSynchronize(stream));
  for (size_t k = 0; k < n; ++k) {
    const cuda::UnsureBeam &u = staging_unsure_[k];
    cuda::BeamFix &f = staging_fixes_[k];
    f.slot = u.slot;
    oracle::beam_end(starts_host_[u.scan], u.angle, u.range, m.wall, m.resolution, &f.x2, &f.y2);
  }
  VG_CUDA_CHECK(cudaMemcpyAsync(fixes_.get(), staging_fixes_.get(), n * sizeof(cuda::BeamFix), cudaMemcpyHostToDevice,
                                stream));
  cuda::launch_exact_fix(fixes_.get(), n, device_beams, stream);
}

}  // namespace cuda_host
}  // namespace vasco
