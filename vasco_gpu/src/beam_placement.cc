#include "vasco_gpu/beam_placement.h"

#include <atomic>
#include <limits>
#include <stdexcept>

#include "vasco_gpu/parallel.h"

namespace vasco {

std::vector<oracle::ScanStart> place_scans(const ScanBatch &batch, const GridGeometry &geo, size_t first,
                                           size_t last) {
  last = std::min(last, batch.num_scans());
  first = std::min(first, last);
  oracle::GridFrame frame;
  frame.size_x = geo.size_x;
  frame.size_y = geo.size_y;
  frame.resolution = geo.resolution;
  frame.theta_offset = geo.theta_offset;
  if (first > 0) oracle::scan_start(frame, batch.x[0], batch.y[0], batch.theta[0]);
  std::vector<oracle::ScanStart> starts(last - first);
  for (size_t s = first; s < last; ++s)
    starts[s - first] = oracle::scan_start(frame, batch.x[s], batch.y[s], batch.theta[s]);
  return starts;
}

PlacedBeams place_beams(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
                        int threads, size_t first, size_t last) {
  last = std::min(last, batch.num_scans());
  first = std::min(first, last);
  const size_t ns = last;
  PlacedBeams out;
  out.first_scan = first;
  out.starts = place_scans(batch, geo, first, last);

  std::vector<uint64_t> used_before(ns + 1, 0);
  for (size_t s = first; s < ns; ++s) {
    const float *r = batch.ranges_of(s);
    uint64_t used = 0;
    for (int b = 0; b < batch.beams_in(s); ++b) used += oracle::beam_used(r[b]) ? 1 : 0;
    used_before[s + 1] = used_before[s] + used;
  }
  const uint64_t nb = used_before.back();
  if (nb > std::numeric_limits<uint32_t>::max())
    throw std::runtime_error("more than 2^32 used beams in one batch");
  out.skipped = (batch.beam_offset[ns] - batch.beam_offset[first]) - nb;
  out.beams.resize(nb);

  std::atomic<size_t> next{first};
  constexpr size_t kChunk = 32;
  const int nt = threads > 0 ? threads : hardware_threads();
  run_on_threads(ns - first < 256 ? 1 : nt, [&](int) {
    for (;;) {
      const size_t s0 = next.fetch_add(kChunk);
      if (s0 >= ns) break;
      for (size_t s = s0; s < std::min(ns, s0 + kChunk); ++s) {
        oracle::SteppedAngles angles{batch.first_angle[s], batch.angle_step[s]};
        const float *r = batch.ranges_of(s);
        uint64_t o = used_before[s];
        double angle = 0;
        for (int b = 0; b < batch.beams_in(s); ++b) {
          angles(b, out.starts[s - first].theta, &angle);
          if (!oracle::beam_used(r[b])) continue;
          PlacedBeam &p = out.beams[o++];
          oracle::beam_end(out.starts[s - first], angle, r[b], params.wall_size, geo.resolution, &p.x2, &p.y2);
          p.scan = static_cast<uint32_t>(s - first);
          p.range = r[b];
        }
      }
    }
  });
  return out;
}

}  // namespace vasco
