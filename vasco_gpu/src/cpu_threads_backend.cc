// cpu_threads: the oracle's result (cpu_double, DESIGN §2) on all cores, bit
// for bit.
//
// The scheme. The grid is cut into stripes of whole x columns (contiguous
// memory, as the grid is x-major); a thread owns one stripe at a time. Stripes
// are handed out dynamically, several per thread, cut so that they carry about
// equal estimated work.
//   1. Scans are placed in order with oracle::scan_start (the first call fixes
//      the start pose).
//   2. In parallel over scans, every used beam's end cell comes from
//      oracle::beam_end, its angle from oracle::SteppedAngles (repeated
//      addition, skipped beams included): the oracle's own code.
//   3. Per beam, the x range of the cells it can update — the steps
//      k <= k_max = min(major_len, table_size - 1) that the oracle walks — and
//      for every stripe the list of beams whose range meets it, in (scan, beam)
//      order. Lines that fail egrid::is_closed_form_line (degenerate, e.g.
//      from a range of -inf) are listed in every stripe.
//   4. Each stripe walks its beams in list order and applies the updates whose
//      cell lies in the stripe: closed-form lines in beam_updates.h's two
//      passes (the box: the stripe's columns), degenerate ones with the
//      oracle's walker, sensor model and odds update (egrid_math.h).
//
// Why this equals the oracle.
//  * Per cell, the oracle's result is the cell's updates applied in (scan,
//    beam) order: a beam visits a cell at most once (the major coordinate
//    strictly moves), and no update reads another cell. Here a cell is written
//    by the one thread that holds its stripe, and a stripe applies its beams
//    in (scan, beam) order (each beam's two passes before the next beam's);
//    so it suffices that each stripe applies, for each beam, exactly the
//    oracle's updates that fall in it.
//  * Closed-form lines (|dx|, |dy| < 2^29): beam_updates::collect gives, of
//    oracle::trace_beam's updates, exactly those whose cell lies in a box —
//    here the stripe's columns of the grid — in walk order (the argument is
//    at the top of beam_updates.cc: x and y move monotonically, so the steps
//    in the box are one run, and the evidence and the stop depend on the
//    cell's squared distance, which never decreases along the walk).
//  * Degenerate lines are walked exactly as oracle::trace_beam walks them, from
//    step 0, stopping at the oracle's stop, in every stripe; each applies only
//    the updates in its own columns. No monotonicity is needed there.
//  * Counts: each oracle update is applied in exactly one stripe.
#include "vasco_gpu/internal/cpu_threads_backend.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <optional>

#include "beam_updates.h"
#include "host_renderer.h"
#include "vasco_gpu/internal/beam_placement.h"
#include "vasco_gpu/internal/oracle.h"
#include "vasco_gpu/internal/parallel.h"
#include "vasco_gpu/internal/timing.h"
#include "vasco_gpu/internal/sensor_params.h"
#include "vasco_gpu/internal/table_cache.h"

namespace vasco {
namespace {

using Clock = std::chrono::steady_clock;

// Stripes per thread: enough slack for the dynamic hand-out to even out the
// estimate's errors, few enough that a beam rarely spans many stripes.
constexpr int kStripesPerThread = 4;
// The per-column work histogram has at most this many buckets.
constexpr int kMaxBuckets = 1 << 16;

// A used beam, in (scan, beam) order.
struct Beam {
  int x2, y2;        // end cell (oracle::beam_end)
  int x_lo, x_hi;    // columns its walk can update (clipped to the grid); x_lo > x_hi: none
  float range;
  uint32_t scan;
  uint32_t degenerate;  // fails egrid::is_closed_form_line: every stripe, walked from step 0
};

struct Context {
  float *cells;
  int size_x, size_y;
  int table_size;
  double resolution;
  egrid::SensorModel<double> model;
  const beam_updates::Evidence *evidence;
};

// Fills b.x_lo, b.x_hi, b.degenerate from the start cell and b.x2, b.y2;
// returns the estimated work per column (steps walked / columns spanned).
double place_beam(Beam &b, const oracle::ScanStart &s, int size_x, int size_y, int table_size) {
  b.degenerate = 0;
  b.x_lo = 0;
  b.x_hi = -1;
  if (table_size <= 0) return 0;  // the oracle's walk loop does not run
  if (!egrid::is_closed_form_line(s.x1, s.y1, b.x2, b.y2)) {
    b.degenerate = 1;
    b.x_hi = size_x - 1;
    return 0;
  }
  const egrid::LineParams p = egrid::line_params(s.x1, s.y1, b.x2, b.y2);
  const int k_max = std::min(p.major_len, table_size - 1);
  int ex, ey;
  egrid::line_cell(p, k_max, &ex, &ey);
  // x and y move monotonically from (x1, y1) to (ex, ey).
  const int y_lo = std::min(s.y1, ey), y_hi = std::max(s.y1, ey);
  if (y_hi < 0 || y_lo >= size_y) return 0;
  const int x_lo = std::min(s.x1, ex), x_hi = std::max(s.x1, ex);
  b.x_lo = std::max(x_lo, 0);
  b.x_hi = std::min(x_hi, size_x - 1);
  return static_cast<double>(k_max + 1) / (static_cast<double>(x_hi) - x_lo + 1);
}

// Applies, of a closed-form beam's updates, those in columns [xa, xb).
uint64_t walk_closed(const Context &c, const Beam &b, const oracle::ScanStart &s, int xa, int xb,
                     beam_updates::BeamUpdates *updates) {
  beam_updates::collect(*c.evidence, {xa, xb, 0, c.size_y}, c.size_y, s.x1, s.y1, b.x2, b.y2, b.range, updates);
  beam_updates::apply(c.cells, *updates, *c.evidence);
  return static_cast<uint64_t>(updates->count);
}

// oracle::trace_beam, applying only the updates in columns [xa, xb).
uint64_t walk_degenerate(const Context &c, const Beam &b, const oracle::ScanStart &s, int xa, int xb) {
  uint64_t updates = 0;
  egrid::walk_beam_cells(s.x1, s.y1, b.x2, b.y2, c.table_size, c.size_x, c.size_y, [&](int cx, int cy, int i, int j) {
    double p;
    const double d = oracle::table_distance(i, j, c.table_size, nullptr, c.resolution);
    if (!egrid::sensor_model(c.model, d, b.range, &p)) return false;
    if (cx >= xa && cx < xb) {
      float &cell = c.cells[egrid::cell_index(cx, cy, c.size_y)];
      cell = egrid::odds_update(cell, c.model.prior, p);
      ++updates;
    }
    return true;
  });
  return updates;
}

// The work per column, in buckets of columns (at most kMaxBuckets).
struct ColumnWork {
  int bucket_w = 1, buckets = 0;
  std::vector<double> weight;  // per bucket
};

// Fills `beams` from the placed ones (x ranges, degenerate flags), in
// parallel over beams, and estimates the work per column on the side (a
// difference array per thread).
ColumnWork place_all(const PlacedBeams &placed, int size_x, int size_y, int T, int nt, Beam *beams) {
  const uint64_t nb = placed.beams.size();
  ColumnWork cw;
  cw.bucket_w = static_cast<int>((static_cast<int64_t>(size_x) + kMaxBuckets - 1) / kMaxBuckets);
  cw.buckets = static_cast<int>((static_cast<int64_t>(size_x) + cw.bucket_w - 1) / cw.bucket_w);
  std::vector<std::vector<double>> diff(nt);
  run_on_threads(nt, [&](int t) {
    std::vector<double> &h = diff[t];
    h.assign(static_cast<size_t>(cw.buckets) + 1, 0.0);
    const uint64_t per = (nb + nt - 1) / nt;
    for (uint64_t o = t * per; o < std::min<uint64_t>(nb, (t + 1) * per); ++o) {
      const PlacedBeam &p = placed.beams[o];
      Beam &b = beams[o];
      b.x2 = p.x2;
      b.y2 = p.y2;
      b.range = p.range;
      b.scan = p.scan;
      const double w = place_beam(b, placed.starts[p.scan], size_x, size_y, T) * cw.bucket_w;
      if (b.x_lo <= b.x_hi && w > 0) {
        h[b.x_lo / cw.bucket_w] += w;
        h[b.x_hi / cw.bucket_w + 1] -= w;
      }
    }
  });
  cw.weight.assign(cw.buckets, 0.0);
  double run = 0;
  for (int k = 0; k < cw.buckets; ++k) {
    for (int t = 0; t < nt; ++t) run += diff[t][k];
    cw.weight[k] = std::max(0.0, run);
  }
  return cw;
}

// Stripes of whole columns: stripe s is [begin[s], begin[s + 1]).
struct Stripes {
  std::vector<int> begin;
  std::vector<double> weight;
  int count() const { return static_cast<int>(begin.size()) - 1; }
  int of(int x) const { return static_cast<int>(std::upper_bound(begin.begin(), begin.end(), x) - begin.begin()) - 1; }
};

// About nt * kStripesPerThread stripes of about equal estimated work.
Stripes cut_stripes(ColumnWork cw, int size_x, int nt) {
  double total = 0;
  for (double w : cw.weight) total += w;
  if (!(total > 0)) {
    std::fill(cw.weight.begin(), cw.weight.end(), 1.0);
    total = cw.buckets;
  }
  const int want = nt == 1 ? 1 : std::min(cw.buckets, nt * kStripesPerThread);
  Stripes st;
  st.begin = {0};
  st.weight = {0};
  double cum = 0;
  for (int k = 0; k < cw.buckets; ++k) {
    cum += cw.weight[k];
    st.weight.back() += cw.weight[k];
    const int edge = std::min(size_x, (k + 1) * cw.bucket_w);
    if (static_cast<int>(st.begin.size()) < want && edge < size_x &&
        cum >= total * static_cast<double>(st.begin.size()) / want) {
      st.begin.push_back(edge);
      st.weight.push_back(0);
    }
  }
  st.begin.push_back(size_x);
  return st;
}

// Per stripe, the beams whose columns meet it, in (scan, beam) order:
// counted per (chunk, stripe), then filled, chunks being contiguous ranges
// of beams, so that each stripe's list keeps the beams' order.
struct Bins {
  std::vector<uint64_t> begin;  // stripe s: beams[begin[s] .. begin[s + 1])
  std::unique_ptr<uint32_t[]> beams;
};

Bins bin_beams(const Beam *beams, uint64_t nb, const Stripes &stripes, int nt) {
  const int nst = stripes.count(), nchunks = nt;
  std::vector<uint64_t> counts(static_cast<size_t>(nchunks) * nst, 0);
  auto for_each_in_chunk = [&](int c, auto &&visit) {
    for (uint64_t i = nb * static_cast<uint64_t>(c) / nchunks; i < nb * static_cast<uint64_t>(c + 1) / nchunks; ++i) {
      const Beam &b = beams[i];
      if (b.x_lo > b.x_hi) continue;
      const int s_hi = stripes.of(b.x_hi);
      for (int s = stripes.of(b.x_lo); s <= s_hi; ++s) visit(i, s);
    }
  };
  run_on_threads(nchunks, [&](int c) {
    uint64_t *cnt = &counts[static_cast<size_t>(c) * nst];
    for_each_in_chunk(c, [&](uint64_t, int s) { ++cnt[s]; });
  });
  Bins bins;
  bins.begin.assign(static_cast<size_t>(nst) + 1, 0);
  std::vector<uint64_t> offsets(counts.size());
  uint64_t o = 0;
  for (int s = 0; s < nst; ++s) {
    bins.begin[s] = o;
    for (int c = 0; c < nchunks; ++c) {
      offsets[static_cast<size_t>(c) * nst + s] = o;
      o += counts[static_cast<size_t>(c) * nst + s];
    }
  }
  bins.begin[nst] = o;
  bins.beams.reset(new uint32_t[std::max<uint64_t>(o, 1)]);
  run_on_threads(nchunks, [&](int c) {
    uint64_t *off = &offsets[static_cast<size_t>(c) * nst];
    for_each_in_chunk(c, [&](uint64_t i, int s) { bins.beams[off[s]++] = static_cast<uint32_t>(i); });
  });
  return bins;
}

// Walks the stripes, heaviest first, handed out dynamically; fills `load`.
void run_stripes(const Context &ctx, const Beam *beams, const std::vector<oracle::ScanStart> &starts,
                 const Stripes &stripes, const Bins &bins, int nt, CpuThreadsLoad *load) {
  const int nst = stripes.count();
  std::vector<int> order(nst);
  for (int s = 0; s < nst; ++s) order[s] = s;
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return stripes.weight[a] > stripes.weight[b]; });
  load->stripe_begin = stripes.begin;
  load->stripe_beams.assign(nst, 0);
  load->stripe_updates.assign(nst, 0);
  load->stripe_thread.assign(nst, -1);
  std::atomic<int> next_stripe{0};
  run_on_threads(std::min(nt, nst), [&](int t) {
    const auto t_busy = Clock::now();
    uint64_t mine = 0;
    beam_updates::BeamUpdates updates(ctx.table_size);
    for (;;) {
      const int q = next_stripe.fetch_add(1);
      if (q >= nst) break;
      const int s = order[q];
      const int xa = stripes.begin[s], xb = stripes.begin[s + 1];
      uint64_t n = 0;
      for (uint64_t e = bins.begin[s]; e < bins.begin[s + 1]; ++e) {
        const Beam &b = beams[bins.beams[e]];
        const oracle::ScanStart &start = starts[b.scan];
        n += b.degenerate ? walk_degenerate(ctx, b, start, xa, xb) : walk_closed(ctx, b, start, xa, xb, &updates);
      }
      load->stripe_beams[s] = bins.begin[s + 1] - bins.begin[s];
      load->stripe_updates[s] = n;
      load->stripe_thread[s] = t;
      mine += n;
    }
    load->thread_updates[t] = mine;
    load->thread_busy_s[t] = seconds_since(t_busy);
  });
}

class CpuThreadsRenderer : public HostGridRenderer {
 public:
  explicit CpuThreadsRenderer(int threads)
      : HostGridRenderer("cpu_threads", true), threads_(threads > 0 ? threads : hardware_threads()) {}

  const CpuThreadsLoad *load() const { return has_load_ ? &load_ : nullptr; }

  void apply_to(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
                const GridGeometry &geo, float *cells, MapStats *stats) override {
    const auto t0 = Clock::now();
    const int nt = threads_;
    const size_t ns = last > first ? last - first : 0;
    const int size_x = geo.size_x, size_y = geo.size_y;
    const int T = params.table_size();
    MapStats st;
    st.scans = ns;

    // 1. Scans and beam end cells, placed by the oracle's own code.
    const PlacedBeams placed = place_beams(batch, geo, params, nt, first, last);
    const std::vector<oracle::ScanStart> &starts = placed.starts;
    const uint64_t nb = placed.beams.size();
    st.beams_used = nb;
    st.beams_skipped = placed.skipped;

    CpuThreadsLoad load;
    load.threads = nt;
    load.thread_updates.assign(nt, 0);
    load.thread_busy_s.assign(nt, 0);
    if (size_x <= 0 || size_y <= 0 || nb == 0 || T <= 0) {
      st.prep_s = seconds_since(t0);
      st.map_s = st.prep_s;
      keep_load(stats, st, std::move(load));
      return;
    }

    // 2. Column ranges and the work estimate; 3. stripes and their beams.
    std::unique_ptr<Beam[]> beams(new Beam[nb]);
    const Stripes stripes = cut_stripes(place_all(placed, size_x, size_y, T, nt, beams.get()), size_x, nt);
    // Kept between calls (a session's inserts).
    evidence_key_.ensure(params, [&] { evidence_.emplace(sensor_model_of(params), params.resolution, T); });
    const Bins bins = bin_beams(beams.get(), nb, stripes, nt);
    st.prep_s = seconds_since(t0);

    // 4. The stripes.
    const auto t_stripes = Clock::now();
    const egrid::SensorModel<double> model = sensor_model_of(params);
    const Context ctx{cells, size_x, size_y, T, geo.resolution, model, &*evidence_};
    run_stripes(ctx, beams.get(), starts, stripes, bins, nt, &load);
    load.stripes_s = seconds_since(t_stripes);
    for (uint64_t n : load.thread_updates) st.cell_updates += n;
    st.map_s = seconds_since(t0);
    keep_load(stats, st, std::move(load));
  }

 private:
  void keep_load(MapStats *stats, const MapStats &st, CpuThreadsLoad &&load) {
    if (stats != nullptr) *stats = st;
    load_ = std::move(load);
    has_load_ = true;
  }

  int threads_;
  std::optional<beam_updates::Evidence> evidence_;
  TableCache evidence_key_;  // of evidence_
  CpuThreadsLoad load_;
  bool has_load_ = false;
};

}  // namespace

std::unique_ptr<HostGridRenderer> make_cpu_threads_renderer(int threads) {
  return std::make_unique<CpuThreadsRenderer>(threads);
}

const CpuThreadsLoad *cpu_threads_load(const Renderer &renderer) {
  const auto *r = dynamic_cast<const CpuThreadsRenderer *>(&renderer);
  return r != nullptr ? r->load() : nullptr;
}

}  // namespace vasco
