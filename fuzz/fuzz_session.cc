// The mapping session under random sequences of insert, render, finish, read
// and budget changes, in the default (growing) frame or a fixed one: a
// cpu_threads session (1 to 4 threads) and a cpu_double session fed the same
// calls must succeed or fail together with the same error code, hold the
// same bytes, and hold a fresh render of their stored scans in their grid
// (frame() is its window); a failed call must change nothing (scans, poses,
// frame, grid).
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <new>
#include <vector>

#include "fuzz_support.h"
#include "vasco_gpu/error.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/renderer.h"

namespace {

void check(bool ok) {
  if (!ok) std::abort();
}

bool same_bytes(const std::vector<float> &a, const std::vector<float> &b) {
  // memcmp may not see the null data() of an empty vector.
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

// What a call may not change when it fails.
struct Snapshot {
  size_t scans = 0;
  vasco::GridGeometry frame;
  std::vector<vasco::Pose> poses;
  std::vector<float> grid;

  explicit Snapshot(const vasco::Mapper &m) : scans(m.num_scans()), frame(m.frame()), poses(m.poses()) {
    if (scans > 0) grid = m.read();
  }
  bool same_as(const Snapshot &o) const {
    if (scans != o.scans || frame.size_x != o.frame.size_x || frame.size_y != o.frame.size_y) return false;
    for (size_t s = 0; s < poses.size(); ++s)
      if (std::memcmp(&poses[s], &o.poses[s], sizeof(vasco::Pose)) != 0) return false;
    return same_bytes(grid, o.grid);
  }
};

// -1: the call succeeded; else the error's code (bad_alloc as OutOfMemory).
int outcome(vasco::Mapper &m, const std::function<void(vasco::Mapper &)> &call) {
  const Snapshot before(m);
  try {
    call(m);
    return -1;
  } catch (const vasco::Error &e) {
    check(Snapshot(m).same_as(before));
    return static_cast<int>(e.code());
  } catch (const std::bad_alloc &) {
    check(Snapshot(m).same_as(before));
    return static_cast<int>(vasco::ErrorCode::OutOfMemory);
  }
}

vasco::MapperParams params_from(fuzz::Bytes &b) {
  vasco::MapperParams p;
  p.resolution = b.in(0.1, 0.5);
  p.range_max = b.in(0.5, 6.0);
  p.range_sure = b.in(0.0, p.range_max);
  p.wall_size = b.in(0.0, 0.5);
  p.p_occ = b.in(0.51, 0.99);
  p.p_emp = b.in(0.01, 0.49);
  p.downsample = 1 + b.u8() % 4;
  return p;
}

double odd_value(fuzz::Bytes &b) {
  switch (b.u8() % 3) {
    case 0: return std::numeric_limits<double>::quiet_NaN();
    case 1: return std::numeric_limits<double>::infinity();
    default: return -1e300;
  }
}

// 1 to 4 scans; now and then a non-finite pose or arrays that disagree.
vasco::ScanBatch batch_from(fuzz::Bytes &b) {
  vasco::ScanBatch batch;
  const int scans = 1 + b.u8() % 4;
  for (int s = 0; s < scans; ++s) {
    const int n = b.u8() % 30;
    std::vector<float> r(static_cast<size_t>(n));
    for (float &v : r) v = b.u8() < 30 ? b.f32() : static_cast<float>(b.in(-1, 8));
    batch.add_scan(b.in(-12, 12), b.in(-12, 12), b.in(-7, 7), b.in(-3.2, 0), b.in(0, 0.2), r.data(), n, s + 1);
  }
  switch (b.u8() % 16) {
    case 0: batch.x[b.u8() % batch.num_scans()] = odd_value(b); break;
    case 1: batch.theta[b.u8() % batch.num_scans()] = odd_value(b); break;
    case 2: batch.beam_offset[1 + b.u8() % batch.num_scans()] += 1 + b.u8(); break;
    case 3: batch.y.pop_back(); break;
    default: break;
  }
  return batch;
}

std::vector<vasco::Pose> poses_from(fuzz::Bytes &b, const vasco::Mapper &m) {
  std::vector<vasco::Pose> p = m.poses();
  const double dx = b.in(-3, 3), dy = b.in(-3, 3), dt = b.in(-1, 1);
  for (vasco::Pose &q : p) q = {q.x + dx, q.y + dy, q.theta + dt};
  const uint8_t odd = b.u8();
  if (odd < 12 && !p.empty()) p[odd % p.size()].y = odd_value(b);
  if (odd >= 250) p.push_back({0, 0, 0});
  return p;
}

vasco::GridWindow window_from(fuzz::Bytes &b, const vasco::Mapper &m) {
  const int sx = m.frame().size_x, sy = m.frame().size_y;
  vasco::GridWindow w{b.u8() % (sx + 2) - 1, b.u8() % (sy + 2) - 1, b.u8() % (sx + 1), b.u8() % (sy + 1)};
  if (b.u8() < 8) w.width = std::numeric_limits<int>::max();
  return w;
}

int border_from(fuzz::Bytes &b) {
  const uint8_t k = b.u8();
  if (k < 10) return std::numeric_limits<int>::max();
  if (k < 20) return -1;
  return k % 30;
}

// frame()'s window of a fresh cpu_double render of m's stored scans in m's
// grid (a grown grid has a margin, where a cell position may round unlike
// in frame() itself: mapper.hpp).
std::vector<float> window_of_fresh(const vasco::Mapper &m) {
  const vasco::GridGeometry &g = m.grid_frame(), &f = m.frame();
  const std::vector<float> all = vasco::render_grid(*vasco::make_renderer("cpu_double"), m.scans(), m.params(), g);
  const int dx = (g.size_x - f.size_x) / 2, dy = (g.size_y - f.size_y) / 2;
  std::vector<float> w(static_cast<size_t>(f.size_x) * f.size_y);
  if (w.empty()) return w;
  for (int x = 0; x < f.size_x; ++x)
    std::memcpy(&w[static_cast<size_t>(x) * f.size_y], &all[static_cast<size_t>(x + dx) * g.size_y + dy],
                sizeof(float) * f.size_y);
  return w;
}

// One call on both sessions: the same outcome, then the same bytes.
void both(vasco::Mapper &a, vasco::Mapper &d, const std::function<void(vasco::Mapper &)> &call) {
  check(outcome(a, call) == outcome(d, call));
  check(a.num_scans() == d.num_scans());
  if (a.num_scans() == 0) return;
  check(a.frame().size_x == d.frame().size_x && a.frame().size_y == d.frame().size_y);
  const std::vector<float> grid = d.read();
  check(same_bytes(a.read(), grid));
  check(same_bytes(window_of_fresh(d), grid));
}

void step(fuzz::Bytes &b, vasco::Mapper &a, vasco::Mapper &d) {
  switch (b.u8() % 6) {
    case 0:
    case 1: {
      const vasco::ScanBatch batch = batch_from(b);
      both(a, d, [&](vasco::Mapper &m) { m.insert(batch); });
      break;
    }
    case 2: {
      const std::vector<vasco::Pose> p = poses_from(b, d);
      both(a, d, [&](vasco::Mapper &m) { m.render(p); });
      break;
    }
    case 3: {
      const int ds = b.u8() % 5, border = border_from(b);
      vasco::FinishedMap fa, fd;
      check(outcome(a, [&](vasco::Mapper &m) { fa = m.finish(ds, border); }) ==
            outcome(d, [&](vasco::Mapper &m) { fd = m.finish(ds, border); }));
      check(fa.size_x == fd.size_x && fa.size_y == fd.size_y && same_bytes(fa.cells, fd.cells));
      break;
    }
    case 4: {
      const vasco::GridWindow w = window_from(b, d);
      both(a, d, [&](vasco::Mapper &m) { (void)m.read(w); });
      break;
    }
    default: {
      const uint64_t budget = b.u8() < 128 ? 0 : uint64_t(b.u8()) << (10 + b.u8() % 14);
      both(a, d, [&](vasco::Mapper &m) { m.set_max_memory_bytes(budget); });
      break;
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fuzz::Bytes b(data, size);
  const vasco::MapperParams p = params_from(b);
  vasco::BackendOptions threads;
  threads.threads = 1 + b.u8() % 4;
  const bool fixed = b.u8() % 2 == 0;
  vasco::GridGeometry frame;
  frame.size_x = 1 + b.u8() % 200;
  frame.size_y = 1 + b.u8() % 200;
  frame.resolution = p.resolution;
  frame.theta_offset = b.in(-4, 4);
  vasco::Mapper a = fixed ? vasco::Mapper(p, frame, "cpu_threads", threads) : vasco::Mapper(p, "cpu_threads", threads);
  vasco::Mapper d = fixed ? vasco::Mapper(p, frame, "cpu_double") : vasco::Mapper(p, "cpu_double");
  for (int i = 0; i < 16 && b.left() > 0; ++i) step(b, a, d);
  return 0;
}
