// update_floor_bench — the memory floor of a render's cell updates, for
// large_site_bench.py's linearity target: every used beam of a log, placed
// by the oracle's code in the log's frame and walked by its line from the
// start cell to the end cell (at most table_size steps, cells inside the
// grid), in the log's order, adding 1 to a float per cell over the box the
// beams reach. Nothing else: no evidence table, no decision, no conversion.
// A render does this and more per update, and the "more" does not depend on
// the grid's size, so the growth of this walk's time per update from a small
// site to a large one (the same scans over a larger area: fewer of a cell's
// updates come while it is still in cache) is what no render that updates
// the cells in the log's order can go below.
//
//   update_floor_bench LOG... [--runs N]   (one JSON object a log; several logs are
//   walked in turn, run after run, so that the ratio between them is of one time)
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "cli_support.h"  // vasco_gpu/app: json_string
#include "huge_pages.h"  // vasco_gpu/src: the CPU backends' host buffers
#include "vasco_gpu/internal/beam_placement.h"
#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/pipeline/log_input.h"

namespace {

struct Box {
  int x0 = 0, y0 = 0, nx = 0, ny = 0;
  size_t cells() const { return static_cast<size_t>(nx) * static_cast<size_t>(ny); }
};

// The box of every beam's start and end cell, clipped to the grid: a line
// is monotone in x and y, so its cells lie in the box of its two ends.
Box reached_box(const vasco::PlacedBeams &placed, const vasco::GridGeometry &geo) {
  int x_lo = geo.size_x, y_lo = geo.size_y, x_hi = -1, y_hi = -1;
  for (const vasco::PlacedBeam &b : placed.beams) {
    const vasco::oracle::ScanStart &s = placed.starts[b.scan];
    x_lo = std::min({x_lo, s.x1, b.x2});
    x_hi = std::max({x_hi, s.x1, b.x2});
    y_lo = std::min({y_lo, s.y1, b.y2});
    y_hi = std::max({y_hi, s.y1, b.y2});
  }
  Box box;
  box.x0 = std::max(x_lo, 0);
  box.y0 = std::max(y_lo, 0);
  box.nx = std::max(0, std::min(x_hi, geo.size_x - 1) - box.x0 + 1);
  box.ny = std::max(0, std::min(y_hi, geo.size_y - 1) - box.y0 + 1);
  return box;
}

// One beam's cells by pointer steps (as cpu_float walks a closed-form line):
// the major axis moves the pointer by one stride a step, the minor axis by
// the other whenever the walk's remainder passes 2a (egrid_math.h
// line_minor_offset, carried step by step). Lines with an end outside the box
// or not in closed form take the oracle's walk.
uint64_t walk_beam(const vasco::oracle::ScanStart &s, const vasco::PlacedBeam &b, const vasco::GridGeometry &geo,
                   const Box &box, int table_size, float *sums) {
  const auto in_box = [&](int x, int y) { return x >= box.x0 && x < box.x0 + box.nx && y >= box.y0 && y < box.y0 + box.ny; };
  uint64_t n = 0;
  if (!in_box(s.x1, s.y1) || !in_box(b.x2, b.y2) || !vasco::egrid::is_closed_form_line(s.x1, s.y1, b.x2, b.y2)) {
    vasco::egrid::walk_beam_cells(s.x1, s.y1, b.x2, b.y2, table_size, geo.size_x, geo.size_y,
                                  [&](int cx, int cy, int, int) {
                                    sums[static_cast<size_t>(cx - box.x0) * box.ny + (cy - box.y0)] += 1.0f;
                                    ++n;
                                    return true;
                                  });
    return n;
  }
  const vasco::egrid::LineParams p = vasco::egrid::line_params(s.x1, s.y1, b.x2, b.y2);
  const ptrdiff_t x_stride = box.ny, y_stride = 1;
  const ptrdiff_t major = (p.steep ? y_stride : x_stride) * p.inc;
  const ptrdiff_t minor = (p.steep ? x_stride : y_stride) * p.inc * (p.flipped ? -1 : 1);
  float *cell = sums + static_cast<ptrdiff_t>(s.x1 - box.x0) * box.ny + (s.y1 - box.y0);
  const int64_t two_a = 2 * static_cast<int64_t>(p.a), two_b = 2 * static_cast<int64_t>(p.b);
  int64_t rem = p.a - (p.inc < 0 ? 1 : 0);
  const int steps = std::min(p.major_len, table_size - 1);
  for (int k = 0; k <= steps; ++k) {
    *cell += 1.0f;
    cell += major;
    rem += two_b;
    if (rem >= two_a) {
      rem -= two_a;
      cell += minor;
    }
  }
  return static_cast<uint64_t>(steps) + 1;
}

uint64_t walk_all(const vasco::PlacedBeams &placed, const vasco::GridGeometry &geo, const Box &box, int table_size,
                  float *sums) {
  uint64_t updates = 0;
  for (const vasco::PlacedBeam &b : placed.beams)
    updates += walk_beam(placed.starts[b.scan], b, geo, box, table_size, sums);
  return updates;
}

// A log's beams, placed, and the box they reach; its sums and timed walks.
struct Site {
  std::string log;
  vasco::LogInput in;
  vasco::PlacedBeams placed;
  Box box;
  std::vector<float> sums;  // on huge pages, as the CPU backends' grids and sums
  std::vector<double> seconds;
  uint64_t updates = 0;
};

double walk_once(Site &site) {
  vasco::assign_on_huge_pages(site.sums, site.box.cells(), 0.0f);  // touched before the clock: no first-touch faults timed
  const auto t0 = std::chrono::steady_clock::now();
  site.updates = walk_all(site.placed, site.in.geo, site.box, site.in.params.table_size(), site.sums.data());
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void print_site(const Site &site) {
  double check = 0;  // read the sums, so that the walk cannot be dropped
  for (size_t i = 0; i < site.sums.size(); i += 4096) check += site.sums[i];
  std::vector<double> seconds = site.seconds;
  std::sort(seconds.begin(), seconds.end());
  const double median = seconds[seconds.size() / 2];
  std::printf("{\"log\": %s, \"cells\": %llu, \"box_cells\": %llu, \"beams\": %llu, \"updates\": %llu, "
              "\"seconds\": %.6f, \"ns_per_update\": %.4f, \"check\": %.1f}\n",
              cli::json_string(site.log).c_str(), static_cast<unsigned long long>(site.in.geo.num_cells()),
              static_cast<unsigned long long>(site.box.cells()),
              static_cast<unsigned long long>(site.placed.beams.size()), static_cast<unsigned long long>(site.updates),
              median, site.updates ? median / static_cast<double>(site.updates) * 1e9 : 0.0, check);
}

}  // namespace

int main(int argc, char **argv) {
  const auto usage = [] {
    std::fprintf(stderr, "usage: update_floor_bench LOG... [--runs N]\n");
    return 2;
  };
  std::vector<std::string> logs;
  int runs = 3;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
    else if (a[0] != '-') logs.push_back(a);
    else return usage();
  }
  if (logs.empty()) return usage();
  std::vector<Site> sites(logs.size());
  for (size_t i = 0; i < logs.size(); ++i) {
    vasco::LogInputOptions lo;
    lo.log = sites[i].log = logs[i];
    try {
      sites[i].in = vasco::load_log_input(lo);
    } catch (const std::exception &e) {
      std::fprintf(stderr, "update_floor_bench: %s\n", e.what());  // it names the log
      return 1;
    }
    sites[i].placed = vasco::place_beams(sites[i].in.batch, sites[i].in.geo, sites[i].in.params, 0, 0,
                                         sites[i].in.batch.num_scans());
    sites[i].box = reached_box(sites[i].placed, sites[i].in.geo);
  }
  // The logs in turn, run after run: a drift of the machine's speed falls on each alike.
  for (int r = 0; r < runs; ++r)
    for (Site &site : sites) site.seconds.push_back(walk_once(site));
  for (const Site &site : sites) print_site(site);
  return 0;
}
