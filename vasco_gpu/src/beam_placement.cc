#include "vasco_gpu/internal/beam_placement.h"

#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "vasco_gpu/internal/parallel.h"

namespace vasco {

std::vector<oracle::ScanStart> place_scans(const ScanBatch &batch, const GridGeometry &geo, size_t first,
                                           size_t last) {
  last = std::min(last, batch.num_scans());
  first = std::min(first, last);
  oracle::GridFrame frame = start_frame(geo, batch);  // scan 0's pose, or the given centre
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

// A beam's end cell is (int)(l + w·cos(angle)/resolution) per axis, with the
// cos and sin of glibc (oracle::beam_end). Calling both for every beam is
// most of the placement's time, so this class derives them from the scan's
// first angle a0 and a per-step table: angle = a0 + d, d = b·step + r, where
// r (the accumulated angle's rounding, |r| < 1e-9 is required) is applied to
// first order:
//   cos(d) = cos(b·step) - sin(b·step)·r,  sin(d) = sin(b·step) + cos(b·step)·r
//   cos(angle) = cos(a0)cos(d) - sin(a0)sin(d),  sin likewise.
// Every term is within an ulp or two of the true value and the dropped r²/2
// is below 1e-18, so the result is within 1e-14 of glibc's. A truncation
// changes only at an integer, so where the approximate coordinate v lies
// farther than egrid::placement_tolerance from every integer, (int)v is the
// oracle's; elsewhere (a few beams in 10^7), and for non-finite or huge
// values, the oracle's own beam_end decides.
class BeamEnds {
 public:
  // Prepares the table for scans of n beams `step` apart.
  void prepare(double step, int n) {
    if (step == step_ && n <= static_cast<int>(cos_.size())) return;
    step_ = step;
    cos_.resize(static_cast<size_t>(n));
    sin_.resize(static_cast<size_t>(n));
    for (int b = 0; b < n; ++b) {
      cos_[static_cast<size_t>(b)] = std::cos(b * step);
      sin_[static_cast<size_t>(b)] = std::sin(b * step);
    }
  }

  // Beam b's end cell; `a0` is the scan's first angle, `angle` beam b's.
  void end_cell(const oracle::ScanStart &s, double a0, double ca0, double sa0, int b, double angle, float range,
                double wall, double resolution, int *x2, int *y2) const {
    const double r = (angle - a0) - b * step_;
    if (std::fabs(r) < 1e-9) {
      const double cb = cos_[static_cast<size_t>(b)], sb = sin_[static_cast<size_t>(b)];
      const double cd = cb - sb * r, sd = sb + cb * r;
      const double k = (static_cast<double>(range) + wall) / resolution;
      const double vx = s.lx + k * (ca0 * cd - sa0 * sd);
      const double vy = s.ly + k * (sa0 * cd + ca0 * sd);
      const double tol = egrid::placement_tolerance(s.lx, s.ly, k);
      if (egrid::far_from_integers(vx, tol) && egrid::far_from_integers(vy, tol)) {
        *x2 = static_cast<int>(vx);
        *y2 = static_cast<int>(vy);
        return;
      }
    }
    oracle::beam_end(s, angle, range, wall, resolution, x2, y2);
  }

 private:
  double step_ = std::nan("");
  std::vector<double> cos_, sin_;
};

namespace {

// The end cells of scan s's used beams, written from out[0] on, with
// `scan_index` in each beam's `scan`; returns how many were written.
size_t place_scan_beams(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
                        const oracle::ScanStart &start, size_t s, uint32_t scan_index, BeamEnds &ends,
                        PlacedBeam *out) {
  oracle::SteppedAngles angles{batch.first_angle[s], batch.angle_step[s]};
  const float *r = batch.ranges_of(s);
  const int n = batch.beams_in(s);
  ends.prepare(batch.angle_step[s], n);
  PlacedBeam *o = out;
  double angle = 0, a0 = 0, ca0 = 1, sa0 = 0;
  for (int b = 0; b < n; ++b) {
    angles(b, start.theta, &angle);  // every beam advances the angle, skipped ones too
    if (b == 0) {
      a0 = angle;
      ca0 = std::cos(a0);
      sa0 = std::sin(a0);
    }
    if (!oracle::beam_used(r[b])) continue;
    ends.end_cell(start, a0, ca0, sa0, b, angle, r[b], params.wall_size, geo.resolution, &o->x2, &o->y2);
    o->scan = scan_index;
    o->range = r[b];
    ++o;
  }
  return static_cast<size_t>(o - out);
}

}  // namespace

ScanBeamPlacer::ScanBeamPlacer() : ends_(std::make_unique<BeamEnds>()) {}
ScanBeamPlacer::~ScanBeamPlacer() = default;

size_t ScanBeamPlacer::place(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
                             const oracle::ScanStart &start, size_t s, uint32_t scan_index, PlacedBeam *out) {
  return place_scan_beams(batch, geo, params, start, s, scan_index, *ends_, out);
}

void place_laid_out_beams(const ScanBatch &batch, const GridGeometry &geo, const MapperParams &params,
                          const BeamLayout &layout, int threads, PlacedBeam *out) {
  for_each_scan_parallel(0, layout.starts.size(), threads, [&](size_t i) {
    thread_local BeamEnds ends;
    place_scan_beams(batch, geo, params, layout.starts[i], layout.first_scan + i, static_cast<uint32_t>(i), ends,
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
