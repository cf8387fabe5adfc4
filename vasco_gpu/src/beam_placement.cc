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

namespace {

// Scans per work item: enough to amortise the shared counter, few enough to
// balance a log whose scans differ in beam count.
constexpr size_t kScansPerItem = 32;

// Runs fn(s) for every s in [s0, s1) on `threads` cores (<= 0: all), in
// items of kScansPerItem scans; small runs stay on the calling thread.
template <class Fn>
void for_each_scan_parallel(size_t s0, size_t s1, int threads, Fn &&fn) {
  std::atomic<size_t> next{s0};
  const int nt = threads > 0 ? threads : hardware_threads();
  run_on_threads(s1 - s0 < 8 * kScansPerItem ? 1 : nt, [&](int) {
    for (;;) {
      const size_t a = next.fetch_add(kScansPerItem);
      if (a >= s1) break;
      for (size_t s = a; s < std::min(s1, a + kScansPerItem); ++s) fn(s);
    }
  });
}

}  // namespace

BeamLayout lay_out_beams(const ScanBatch &batch, const GridGeometry &geo, int threads, size_t first, size_t last) {
  last = std::min(last, batch.num_scans());
  first = std::min(first, last);
  BeamLayout layout;
  layout.first_scan = first;
  layout.starts = place_scans(batch, geo, first, last);
  const size_t n = last - first;
  layout.used_before.assign(n + 1, 0);
  for_each_scan_parallel(0, n, threads, [&](size_t i) {
    const float *r = batch.ranges_of(first + i);
    uint64_t used = 0;
    for (int b = 0; b < batch.beams_in(first + i); ++b) used += oracle::beam_used(r[b]) ? 1 : 0;
    layout.used_before[i + 1] = used;
  });
  for (size_t i = 0; i < n; ++i) layout.used_before[i + 1] += layout.used_before[i];
  if (layout.used() > std::numeric_limits<uint32_t>::max())
    throw std::runtime_error("more than 2^32 used beams in one batch");
  layout.skipped = (batch.beam_offset[last] - batch.beam_offset[first]) - layout.used();
  return layout;
}

namespace {

// The end cells of scan s's used beams, written from out[0] on, with
// `scan_index` in each beam's `scan`.
void place_scan_beams(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
                      const oracle::ScanStart &start, size_t s, uint32_t scan_index, PlacedBeam *out) {
  oracle::SteppedAngles angles{batch.first_angle[s], batch.angle_step[s]};
  const float *r = batch.ranges_of(s);
  PlacedBeam *o = out;
  double angle = 0;
  for (int b = 0; b < batch.beams_in(s); ++b) {
    angles(b, start.theta, &angle);  // every beam advances the angle, skipped ones too
    if (!oracle::beam_used(r[b])) continue;
    oracle::beam_end(start, angle, r[b], params.wall_size, geo.resolution, &o->x2, &o->y2);
    o->scan = scan_index;
    o->range = r[b];
    ++o;
  }
}

}  // namespace

void place_laid_out_beams(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
                          const BeamLayout &layout, int threads, PlacedBeam *out) {
  for_each_scan_parallel(0, layout.starts.size(), threads, [&](size_t i) {
    place_scan_beams(batch, geo, params, layout.starts[i], layout.first_scan + i, static_cast<uint32_t>(i),
                     out + layout.used_before[i]);
  });
}

PlacedBeams place_beams(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
                        int threads, size_t first, size_t last) {
  BeamLayout layout = lay_out_beams(batch, geo, threads, first, last);
  PlacedBeams out;
  out.first_scan = layout.first_scan;
  out.skipped = layout.skipped;
  out.beams.resize(layout.used());
  place_laid_out_beams(batch, geo, params, layout, threads, out.beams.data());
  out.starts = std::move(layout.starts);
  return out;
}

}  // namespace vasco
